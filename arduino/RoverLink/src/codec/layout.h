// Message layouts: the generated protocol describes every message as a small byte table in flash,
// and these three functions walk it. One generic packer, unpacker and range checker serve every
// message, instead of unrolled code per message (which cost several KB of AVR flash).
//
// A layout (generated into src/generated/roverlink_protocol.cpp, PROGMEM on AVR) is:
//
//   PAYLOAD_SIZE, PAYLOAD_MAX, field count,
//   then per field, in spec order:
//     code                       element width in bytes | kind | check | ARRAY (constants below)
//     offsetof(struct, field)    where the field's first element is in the message struct
//     [count]                    ARRAY: elements of a fixed array; 0 marks the variable-length
//     [max_len, offsetof(len)]     last field (bytes): its most elements and its `<name>_len`
//     [check data]               in the field's width w, little-endian:
//                                  CHECK_RANGE   lo (w), hi (w): the spec range, for check_ranges()
//                                  CHECK_VALUES  lo (w), hi (w), n, n bitmap bytes: the values
//                                                unpack() accepts (an enum's, or 0..0x7F for ASCII
//                                                chars); n = 0: all of lo..hi, else bit i set =
//                                                lo + i is a value (hi - lo < 256)
//                                  CHECK_FLAGS   mask (w): the bits unpack() accepts
//
// Every element is moved field by field with shifts (little-endian on the wire whatever the
// host), each struct member read or written through a variable of its own width: never a struct
// memcpy. Ranges are compared in integers, f32 ones as IEEE-754 bit patterns mapped to an order
// (so a range check needs no floating-point code): NaN is outside every range, and the generator
// writes a float range starting or ending at 0.0 with -0.0 at the low end and 0.0 at the high end,
// so both zeros pass as the spec's comparison does.
#ifndef ROVERLINK_CODEC_LAYOUT_H
#define ROVERLINK_CODEC_LAYOUT_H

#include <stdint.h>

#include "compiler.h"

namespace roverlink {
namespace layout {

// Field code, bits 0..2: the element's width in bytes (1, 2 or 4); bits 3..4: its kind.
enum : uint8_t {
    WIDTH_MASK = 0x07,
    KIND_UNSIGNED = 0x00,
    KIND_SIGNED = 0x08,
    KIND_FLOAT = 0x10,
    KIND_MASK = 0x18,
};
enum : uint8_t {
    WIRE_U8 = 1 | KIND_UNSIGNED,
    WIRE_U16 = 2 | KIND_UNSIGNED,
    WIRE_U32 = 4 | KIND_UNSIGNED,
    WIRE_I8 = 1 | KIND_SIGNED,
    WIRE_I16 = 2 | KIND_SIGNED,
    WIRE_I32 = 4 | KIND_SIGNED,
    WIRE_F32 = 4 | KIND_FLOAT,
};
// Field code, bits 5..6: what is checked; bit 7: an array.
enum : uint8_t {
    CHECK_NONE = 0x00,
    CHECK_RANGE = 0x20,
    CHECK_VALUES = 0x40,
    CHECK_FLAGS = 0x60,
    CHECK_MASK = 0x60,
    ARRAY = 0x80,
};
static const uint8_t HEADER_SIZE = 3;
static const uint8_t ALL_VALID = 0xFF;  // check_ranges(): every field in range

// Writes the payload of `msg` (the struct the layout describes) and returns its length.
uint8_t pack(const uint8_t* layout, const void* msg, uint8_t* payload);

// Fills `msg` from `len` payload bytes. False when the length does not fit the layout, or an
// element fails its CHECK_VALUES or CHECK_FLAGS (msg is then partly written).
bool unpack(const uint8_t* layout, const uint8_t* payload, uint8_t len, void* msg);

// Index of the first field with an element outside its CHECK_RANGE, or ALL_VALID.
uint8_t check_ranges(const uint8_t* layout, const void* msg);

}  // namespace layout
}  // namespace roverlink

#endif  // ROVERLINK_CODEC_LAYOUT_H
