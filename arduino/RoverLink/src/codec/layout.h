// Message layouts: the generated protocol describes every message as a small byte table in flash,
// and these three functions walk it. One generic packer, unpacker and range checker serve every
// message, instead of unrolled code per message (which cost several KB of AVR flash).
//
// A layout (generated into src/generated/roverlink_protocol.cpp, PROGMEM on AVR) is:
//
//   PAYLOAD_SIZE, PAYLOAD_MAX, field count,
//   then per field, in spec order:
//     code                       wire type | check | ARRAY (constants below)
//     offsetof(struct, field)    where the field's first element is in the message struct
//     [count]                    ARRAY: elements of a fixed array; 0 marks the variable-length
//     [max_len, offsetof(len)]     last field: its most elements and its `<name>_len` member
//     [check data]               in the field's wire width w, little-endian:
//                                  CHECK_RANGE      lo (w), hi (w): the spec range (check_ranges)
//                                  CHECK_VALUES     lo (w), hi (w): contiguous enum values, or
//                                                   0..0x7F for ASCII chars (unpack)
//                                  CHECK_VALUE_SET  first (w), n, n bytes: bit i set = first + i
//                                                   is a value of the enum (unpack)
//                                  CHECK_FLAGS      mask (w): the bits the spec defines (unpack)
//
// Every element is moved field by field with shifts (little-endian on the wire whatever the
// host), each struct member read or written through a variable of its own width: never a struct
// memcpy. f32 ranges hold IEEE-754 bit patterns and are compared in integers (NaN is outside every
// range; -0.0 equals 0.0), so range checks need no floating-point code.
#ifndef ROVERLINK_CODEC_LAYOUT_H
#define ROVERLINK_CODEC_LAYOUT_H

#include <stdint.h>

#include "compiler.h"

namespace roverlink {
namespace layout {

// Field code, bits 0..1: log2 of the element width; bits 2..3: the kind of number.
enum : uint8_t {
    WIDTH_MASK = 0x03,
    KIND_UNSIGNED = 0x00,
    KIND_SIGNED = 0x04,
    KIND_FLOAT = 0x08,
    KIND_MASK = 0x0C,
};
enum : uint8_t {
    WIRE_U8 = 0x00 | KIND_UNSIGNED,
    WIRE_U16 = 0x01 | KIND_UNSIGNED,
    WIRE_U32 = 0x02 | KIND_UNSIGNED,
    WIRE_I8 = 0x00 | KIND_SIGNED,
    WIRE_I16 = 0x01 | KIND_SIGNED,
    WIRE_I32 = 0x02 | KIND_SIGNED,
    WIRE_F32 = 0x02 | KIND_FLOAT,
};
// Field code, bits 4..6: what is checked; bit 7: an array.
enum : uint8_t {
    CHECK_NONE = 0x00,
    CHECK_RANGE = 0x10,
    CHECK_VALUES = 0x20,
    CHECK_VALUE_SET = 0x30,
    CHECK_FLAGS = 0x40,
    CHECK_MASK = 0x70,
    ARRAY = 0x80,
};
static const uint8_t HEADER_SIZE = 3;
static const uint8_t ALL_VALID = 0xFF;  // check_ranges(): every field in range

// Writes the payload of `msg` (the struct the layout describes) and returns its length.
uint8_t pack(const uint8_t* layout, const void* msg, uint8_t* payload);

// Fills `msg` from `len` payload bytes. False when the length does not fit the layout, or an
// element fails its CHECK_VALUES, CHECK_VALUE_SET or CHECK_FLAGS (msg is then partly written).
bool unpack(const uint8_t* layout, const uint8_t* payload, uint8_t len, void* msg);

// Index of the first field with an element outside its CHECK_RANGE, or ALL_VALID.
uint8_t check_ranges(const uint8_t* layout, const void* msg);

}  // namespace layout
}  // namespace roverlink

#endif  // ROVERLINK_CODEC_LAYOUT_H
