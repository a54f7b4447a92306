// Configuration: validation of a SET_CONFIG, and the EEPROM image (config + PID gains, with a
// version and a CRC-16) that SAVE_CONFIG writes and boot reads.
//
// EEPROM layout (addresses in bytes):
//   0x000..0x003  boot counter, u32 little-endian, +1 every boot (mixed into boot_id)
//   0x010..       config image:
//                   'R' 'L' IMAGE_VERSION SetConfig::CRC_EXTRA SetPid::CRC_EXTRA
//                   SET_CONFIG payload (the wire packing, little-endian)
//                   one SET_PID payload per wheel (wheel index, kp, ki, kd, kf, ks)
//                   CRC-16/CCITT-FALSE of everything above, little-endian
// The two CRC_EXTRA bytes change whenever the spec changes those messages' layout, so an image
// written by another firmware version reads as "another version" and the defaults are used.
#ifndef ROVERLINK_CORE_CONFIG_H
#define ROVERLINK_CORE_CONFIG_H

#include <stddef.h>
#include <stdint.h>

#include "../generated/roverlink_protocol.h"
#include "../hal/board.h"
#include "control.h"

namespace roverlink {
namespace config {

static const uint16_t BOOT_COUNTER_ADDR = 0x000;
static const uint16_t IMAGE_ADDR = 0x010;
static const uint8_t IMAGE_VERSION = 1;
static const uint8_t IMAGE_HEADER = 5;
static const uint8_t IMAGE_FIRST_CHUNK = IMAGE_HEADER + proto::SetConfig::PAYLOAD_SIZE;
static const uint16_t IMAGE_SIZE =
    IMAGE_FIRST_CHUNK + proto::WHEEL_COUNT * proto::SetPid::PAYLOAD_SIZE + 2;

// SET_CONFIG field indices named by the consistency rules (NACK(INVALID_CONFIG).detail).
static const uint8_t FIELD_STEERING_CENTER = proto::SetConfig::FIELD_STEERING_CENTER_CDEG;
static const uint8_t FIELD_SERVO_MIN = proto::SetConfig::FIELD_SERVO_MIN_US;
static const uint8_t FIELD_ESC_MIN = proto::SetConfig::FIELD_ESC_MIN_US;
static const uint8_t FIELD_ESC_NEUTRAL = proto::SetConfig::FIELD_ESC_NEUTRAL_US;

// Checks ranges (generated check_ranges: OUT_OF_RANGE, detail = field index) and consistency
// (INVALID_CONFIG, detail = the first field, in message order, of the first rule broken):
//   steering_min <= steering_center <= steering_max   -> steering_center_cdeg
//   servo_min_us < servo_max_us                        -> servo_min_us
//   esc_min_us < esc_neutral_us                        -> esc_min_us
//   esc_neutral_us < esc_max_us                        -> esc_neutral_us
bool validate(const proto::SetConfig& c, proto::NackReason& reason, uint8_t& detail);

// The consistency rules alone (the ranges already checked): the field index validate() would
// give with INVALID_CONFIG, or proto::ALL_FIELDS_VALID.
uint8_t inconsistent_field(const proto::SetConfig& c);

enum class LoadResult : uint8_t {
    OK = 0,
    NO_IMAGE,  // never saved, erased, or written by another firmware version
    BAD_CRC,   // corrupt
    INVALID,   // CRC good but the values fail validation
};

// Reads the image; on OK fills `cfg` and `gains`, otherwise leaves them alone. `scratch` must
// hold IMAGE_FIRST_CHUNK bytes.
LoadResult load(Board& board, proto::SetConfig& cfg, control::Gains gains[proto::WHEEL_COUNT], uint8_t* scratch);

// Writes the image (only the bytes that differ, to spare the cells) and reads every byte back.
// False when a write fails or the read-back differs.
bool save(Board& board, const proto::SetConfig& cfg, const control::Gains gains[proto::WHEEL_COUNT],
          uint8_t* scratch);

// Reads the boot counter, stores it + 1 and returns the new value (0 when there is no EEPROM).
uint32_t bump_boot_counter(Board& board);

}  // namespace config
}  // namespace roverlink

#endif  // ROVERLINK_CORE_CONFIG_H
