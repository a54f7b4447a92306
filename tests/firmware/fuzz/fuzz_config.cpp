// Fuzz target: the EEPROM configuration image (arduino/RoverLink/src/core/config.cpp) and the
// boot that reads it, fed arbitrary images.
//
// Input: byte 0 holds options, the rest is the image (config::IMAGE_SIZE bytes at IMAGE_ADDR,
// 0xFF past the input's end as on a blank EEPROM). Option bit 0 writes the image's own header,
// bit 1 recomputes its CRC: random bytes then reach the value checks, which they would almost
// never reach with a CRC-16 to guess. Checked (FUZZ_CHECK aborts):
//   - load() accepts exactly the images whose header and CRC are right and whose values pass the
//     same checks as SET_CONFIG and SET_PID (a reference written here from docs/firmware.md), and
//     on refusal leaves the caller's config and gains untouched;
//   - what it accepts is within the spec and consistent, and save() of it writes the same image
//     back byte for byte, which load() accepts again;
//   - the firmware booting on that EEPROM runs the loaded config or the robot's defaults, and says
//     which (the CONFIG_DEFAULTS status bit).
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <RoverLink.h>

#include "fuzz_check.h"
#include "hal/native/memory_stream.h"
#include "hal/native/native_board.h"
#include "profiles.h"

using namespace roverlink;

namespace {

const uint8_t HEADER[config::IMAGE_HEADER] = {'R', 'L', config::IMAGE_VERSION, proto::SetConfig::CRC_EXTRA,
                                               proto::SetPid::CRC_EXTRA};

uint16_t get_u16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }

// docs/firmware.md's image rule, from the wire layout: header, SET_CONFIG payload valid as a
// SET_CONFIG would be, SET_PID payloads for wheels 0, 1 in range, CRC-16 of all before it.
config::LoadResult reference_verdict(const uint8_t* image) {
    if (memcmp(image, HEADER, sizeof HEADER) != 0) {
        return config::LoadResult::NO_IMAGE;
    }
    const size_t body = config::IMAGE_SIZE - 2;
    if (crc16(image, body) != get_u16(image + body)) {
        return config::LoadResult::BAD_CRC;
    }
    proto::SetConfig c;
    if (!proto::unpack(image + config::IMAGE_HEADER, proto::SetConfig::PAYLOAD_SIZE, c) ||
        proto::check_ranges(c) != proto::ALL_FIELDS_VALID || config::inconsistent_field(c) != proto::ALL_FIELDS_VALID) {
        return config::LoadResult::INVALID;
    }
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        proto::SetPid p;
        const uint8_t* at = image + config::IMAGE_FIRST_CHUNK + w * proto::SetPid::PAYLOAD_SIZE;
        if (!proto::unpack(at, proto::SetPid::PAYLOAD_SIZE, p) || p.wheel != w ||
            proto::check_ranges(p) != proto::ALL_FIELDS_VALID) {
            return config::LoadResult::INVALID;
        }
    }
    return config::LoadResult::OK;
}

void check_boot(NativeBoard& board, const proto::SetConfig* loaded, const control::Gains* gains, uint8_t pick) {
    const sim_profiles::Profile* profile = sim_profiles::at(pick % sim_profiles::count());
    MemoryStream port;
    Firmware fw(port, board, *profile->robot);
    fw.begin();
    const proto::SetConfig expected = loaded != 0 ? *loaded : profile->robot->default_config();
    FUZZ_CHECK(memcmp(&fw.config(), &expected, sizeof expected) == 0);
    FUZZ_CHECK(((fw.status() & proto::Status::CONFIG_DEFAULTS) != 0) == (loaded == 0));
    if (gains != 0) {
        FUZZ_CHECK(memcmp(&fw.gains(0), &gains[0], sizeof gains[0]) == 0);
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) {
        return 0;
    }
    const uint8_t options = data[0];
    uint8_t image[config::IMAGE_SIZE];
    memset(image, 0xFF, sizeof image);
    memcpy(image, data + 1, size - 1 < sizeof image ? size - 1 : sizeof image);
    if (options & 1) {
        memcpy(image, HEADER, sizeof HEADER);
    }
    if (options & 2) {
        const uint16_t crc = crc16(image, config::IMAGE_SIZE - 2);
        image[config::IMAGE_SIZE - 2] = static_cast<uint8_t>(crc);
        image[config::IMAGE_SIZE - 1] = static_cast<uint8_t>(crc >> 8);
    }
    NativeBoard board(1);
    FUZZ_CHECK(board.eeprom_write(config::IMAGE_ADDR, image, sizeof image));

    // Sentinels: a refused image must leave them alone.
    proto::SetConfig cfg;
    memset(&cfg, 0xA5, sizeof cfg);
    control::Gains gains[proto::WHEEL_COUNT];
    memset(gains, 0x5A, sizeof gains);
    proto::SetConfig cfg_before = cfg;
    control::Gains gains_before[proto::WHEEL_COUNT];
    memcpy(gains_before, gains, sizeof gains);
    uint8_t scratch[config::IMAGE_FIRST_CHUNK];
    const config::LoadResult r = config::load(board, cfg, gains, scratch);
    FUZZ_CHECK(r == reference_verdict(image));
    if (r != config::LoadResult::OK) {
        FUZZ_CHECK(memcmp(&cfg, &cfg_before, sizeof cfg) == 0 && memcmp(gains, gains_before, sizeof gains) == 0);
        check_boot(board, 0, 0, options >> 2);
        return 0;
    }
    FUZZ_CHECK(proto::check_ranges(cfg) == proto::ALL_FIELDS_VALID);
    FUZZ_CHECK(config::inconsistent_field(cfg) == proto::ALL_FIELDS_VALID);

    // save() writes the same image back, and load() takes it again.
    NativeBoard other(2);
    FUZZ_CHECK(config::save(other, cfg, gains, scratch));
    FUZZ_CHECK(memcmp(other.eeprom() + config::IMAGE_ADDR, image, sizeof image) == 0);
    proto::SetConfig again;
    control::Gains gains_again[proto::WHEEL_COUNT];
    FUZZ_CHECK(config::load(other, again, gains_again, scratch) == config::LoadResult::OK);
    FUZZ_CHECK(memcmp(&again, &cfg, sizeof cfg) == 0 && memcmp(gains_again, gains, sizeof gains) == 0);
    check_boot(board, &cfg, gains, options >> 2);
    return 0;
}
