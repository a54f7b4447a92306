#include "config.h"

#include "../codec/codec.h"
#include "../codec/wire.h"

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

void write_header(uint8_t* p) {
    p[0] = 'R';
    p[1] = 'L';
    p[2] = IMAGE_VERSION;
    p[3] = proto::SetConfig::CRC_EXTRA;
    p[4] = proto::SetPid::CRC_EXTRA;
}

uint8_t pack_gains(uint8_t wheel, const control::Gains& g, uint8_t* out) {
    proto::SetPid p;
    p.wheel = wheel;
    p.kp = g.kp;
    p.ki = g.ki;
    p.kd = g.kd;
    p.kf = g.kf;
    return proto::pack(p, out);
}

// Writes the bytes of `data` that differ from the EEPROM, then verifies all of them.
bool write_verified(Board& board, uint16_t addr, const uint8_t* data, uint8_t len) {
    for (uint8_t i = 0; i < len; ++i) {
        uint8_t cur;
        if (!board.eeprom_read(static_cast<uint16_t>(addr + i), &cur, 1)) {
            return false;
        }
        if (cur != data[i] && !board.eeprom_write(static_cast<uint16_t>(addr + i), data + i, 1)) {
            return false;
        }
    }
    for (uint8_t i = 0; i < len; ++i) {
        uint8_t back;
        if (!board.eeprom_read(static_cast<uint16_t>(addr + i), &back, 1) || back != data[i]) {
            return false;
        }
    }
    return true;
}

}  // namespace

LoadResult load(Board& board, proto::SetConfig& cfg, control::Gains gains[proto::WHEEL_COUNT], uint8_t* scratch) {
    // 1. Header, then the CRC over the whole image, a byte at a time (no second buffer).
    uint8_t header[IMAGE_HEADER];
    write_header(header);
    uint16_t crc = CRC16_INIT;
    for (uint16_t i = 0; i < IMAGE_SIZE - 2u; ++i) {
        uint8_t b;
        if (!board.eeprom_read(static_cast<uint16_t>(IMAGE_ADDR + i), &b, 1) || (i < IMAGE_HEADER && b != header[i])) {
            return LoadResult::NO_IMAGE;
        }
        crc = crc16_update(crc, b);
    }
    uint8_t stored[2];
    if (!board.eeprom_read(static_cast<uint16_t>(IMAGE_ADDR + IMAGE_SIZE - 2u), stored, 2)) {
        return LoadResult::NO_IMAGE;
    }
    if (wire::get_u16(stored) != crc) {
        return LoadResult::BAD_CRC;
    }
    // 2. The values, checked as SET_CONFIG and SET_PID would be.
    proto::SetConfig c;
    proto::NackReason reason;
    uint8_t detail;
    if (!board.eeprom_read(IMAGE_ADDR + IMAGE_HEADER, scratch, proto::SetConfig::PAYLOAD_SIZE) ||
        !proto::unpack(scratch, proto::SetConfig::PAYLOAD_SIZE, c) || !validate(c, reason, detail)) {
        return LoadResult::INVALID;
    }
    control::Gains g[proto::WHEEL_COUNT];
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        proto::SetPid p;
        const uint16_t addr = static_cast<uint16_t>(IMAGE_ADDR + IMAGE_FIRST_CHUNK + w * proto::SetPid::PAYLOAD_SIZE);
        if (!board.eeprom_read(addr, scratch, proto::SetPid::PAYLOAD_SIZE) ||
            !proto::unpack(scratch, proto::SetPid::PAYLOAD_SIZE, p) || p.wheel != w ||
            proto::check_ranges(p) != proto::ALL_FIELDS_VALID) {
            return LoadResult::INVALID;
        }
        g[w].kp = p.kp;
        g[w].ki = p.ki;
        g[w].kd = p.kd;
        g[w].kf = p.kf;
    }
    cfg = c;
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        gains[w] = g[w];
    }
    return LoadResult::OK;
}

bool save(Board& board, const proto::SetConfig& cfg, const control::Gains gains[proto::WHEEL_COUNT],
          uint8_t* scratch) {
    uint16_t addr = IMAGE_ADDR;
    write_header(scratch);
    const uint8_t n = static_cast<uint8_t>(IMAGE_HEADER + proto::pack(cfg, scratch + IMAGE_HEADER));
    uint16_t crc = crc16(scratch, n);
    if (!write_verified(board, addr, scratch, n)) {
        return false;
    }
    addr = static_cast<uint16_t>(addr + n);
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        const uint8_t k = pack_gains(w, gains[w], scratch);
        crc = crc16(scratch, k, crc);
        if (!write_verified(board, addr, scratch, k)) {
            return false;
        }
        addr = static_cast<uint16_t>(addr + k);
    }
    scratch[0] = static_cast<uint8_t>(crc);
    scratch[1] = static_cast<uint8_t>(crc >> 8);
    return write_verified(board, addr, scratch, 2);
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
