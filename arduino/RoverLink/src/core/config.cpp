#include "config.h"

#include <string.h>

#include "../codec/codec.h"
#include "../wire/wire.h"

namespace roverlink {
namespace config {

static_assert(IMAGE_FIRST_CHUNK <= proto::MAX_FRAME, "the EEPROM image chunks use the TX frame buffer");
static_assert(IMAGE_ADDR >= BOOT_COUNTER_ADDR + 4, "the image must not overlap the boot counter");

bool validate(const proto::SetConfig& c, proto::NackReason& reason, uint8_t& detail) {
    detail = proto::check_ranges(c);
    reason = proto::NackReason::OUT_OF_RANGE;
    if (detail == proto::ALL_FIELDS_VALID) {
        detail = inconsistent_field(c);
        reason = proto::NackReason::INVALID_CONFIG;
    }
    return detail == proto::ALL_FIELDS_VALID;
}

uint8_t inconsistent_field(const proto::SetConfig& c) {
    if (c.steering_min_cdeg > c.steering_center_cdeg || c.steering_center_cdeg > c.steering_max_cdeg) {
        return FIELD_STEERING_CENTER;
    }
    if (c.servo_min_us >= c.servo_max_us) {
        return FIELD_SERVO_MIN;
    }
    if (c.esc_min_us >= c.esc_neutral_us) {
        return FIELD_ESC_MIN;
    }
    if (c.esc_neutral_us >= c.esc_max_us) {
        return FIELD_ESC_NEUTRAL;
    }
    return proto::ALL_FIELDS_VALID;
}

namespace {

const uint8_t HEADER[IMAGE_HEADER] ROVERLINK_PROGMEM = {'R', 'L', IMAGE_VERSION, proto::SetConfig::CRC_EXTRA,
                                                         proto::SetPid::CRC_EXTRA};

// The image is a run of chunks: the header, the SET_CONFIG payload, one SET_PID payload per wheel
// (then the CRC of all of them). Both load() and save() go through it chunk by chunk in `scratch`.
const uint8_t CHUNKS = 2 + proto::WHEEL_COUNT;
static_assert(IMAGE_SIZE == IMAGE_HEADER + proto::SetConfig::PAYLOAD_SIZE +
                                proto::WHEEL_COUNT * proto::SetPid::PAYLOAD_SIZE + 2,
              "the image is its chunks and a CRC");

uint8_t chunk_size(uint8_t k) {
    if (k == 0) {
        return IMAGE_HEADER;
    }
    const uint8_t config = proto::SetConfig::PAYLOAD_SIZE;
    const uint8_t pid = proto::SetPid::PAYLOAD_SIZE;
    return k == 1 ? config : pid;
}

// Writes the bytes of `data` that differ from the EEPROM, reading each back.
bool write_verified(Board& board, uint16_t addr, const uint8_t* data, uint8_t len) {
    for (uint8_t i = 0; i < len; ++i, ++addr) {
        uint8_t cur;
        if (!board.eeprom_read(addr, &cur, 1) ||
            (cur != data[i] && (!board.eeprom_write(addr, data + i, 1) || !board.eeprom_read(addr, &cur, 1) ||
                                cur != data[i]))) {
            return false;
        }
    }
    return true;
}

}  // namespace

LoadResult load(Board& board, proto::SetConfig& cfg, control::Gains gains[proto::WHEEL_COUNT], uint8_t* scratch) {
    // One pass: each chunk is read, added to the CRC and parsed; the verdict comes in the order
    // unreadable or foreign image, CRC, values (checked as SET_CONFIG and SET_PID would be).
    proto::SetConfig c;
    control::Gains g[proto::WHEEL_COUNT];
    bool valid = true;
    uint16_t crc = CRC16_INIT;
    uint16_t addr = IMAGE_ADDR;
    for (uint8_t k = 0; k < CHUNKS; ++k) {
        const uint8_t n = chunk_size(k);
        if (!board.eeprom_read(addr, scratch, n)) {
            return LoadResult::NO_IMAGE;
        }
        addr = static_cast<uint16_t>(addr + n);
        crc = crc16(scratch, n, crc);
        if (k == 0) {
            for (uint8_t i = 0; i < n; ++i) {
                if (scratch[i] != ROVERLINK_READ_BYTE(HEADER + i)) {
                    return LoadResult::NO_IMAGE;  // blank, or written by another version
                }
            }
        } else if (k == 1) {
            proto::NackReason reason;
            uint8_t detail;
            valid = proto::unpack(scratch, n, c) && validate(c, reason, detail);
        } else {
            proto::SetPid p;
            const uint8_t w = static_cast<uint8_t>(k - 2);
            valid = valid && proto::unpack(scratch, n, p) && p.wheel == w &&
                    proto::check_ranges(p) == proto::ALL_FIELDS_VALID;
            control::gains_from(g[w], p);
        }
    }
    if (!board.eeprom_read(addr, scratch, 2)) {
        return LoadResult::NO_IMAGE;
    }
    if (wire::get_u16(scratch) != crc) {
        return LoadResult::BAD_CRC;
    }
    if (!valid) {
        return LoadResult::INVALID;
    }
    cfg = c;
    memcpy(gains, g, sizeof g);
    return LoadResult::OK;
}

bool save(Board& board, const proto::SetConfig& cfg, const control::Gains gains[proto::WHEEL_COUNT],
          uint8_t* scratch) {
    uint16_t crc = CRC16_INIT;
    uint16_t addr = IMAGE_ADDR;
    for (uint8_t k = 0; k <= CHUNKS; ++k) {
        uint8_t n = 2;
        if (k == 0) {
            for (n = 0; n < IMAGE_HEADER; ++n) {
                scratch[n] = ROVERLINK_READ_BYTE(HEADER + n);
            }
        } else if (k == 1) {
            n = proto::pack(cfg, scratch);
        } else if (k < CHUNKS) {
            const uint8_t w = static_cast<uint8_t>(k - 2);
            proto::SetPid p;
            p.wheel = w;
            control::gains_to(p, gains[w]);
            n = proto::pack(p, scratch);
        } else {
            wire::put_u16(scratch, crc);  // the last chunk: the CRC of the others
        }
        if (k < CHUNKS) {
            crc = crc16(scratch, n, crc);
        }
        if (!write_verified(board, addr, scratch, n)) {
            return false;
        }
        addr = static_cast<uint16_t>(addr + n);
    }
    return true;
}

uint32_t bump_boot_counter(Board& board) {
    uint8_t b[4];
    if (!board.eeprom_read(BOOT_COUNTER_ADDR, b, 4)) {
        return 0;
    }
    uint32_t n = wire::get_u32(b) + 1u;
    wire::put_u32(b, n);
    board.eeprom_write(BOOT_COUNTER_ADDR, b, 4);  // a failed write only weakens boot_id's entropy
    return n;
}

}  // namespace config
}  // namespace roverlink
