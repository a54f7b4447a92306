// Message layouts. Every generated message struct is the little-endian wire image of its payload
// (packed, members in spec order with their wire widths, offsets static_asserted by the generator),
// so pack() and unpack() are a copy; what remains per message is a small byte table in flash of the
// fields that have something to check, walked by the two functions below. One walker serves every
// message instead of unrolled code per message (which cost several KB of AVR flash).
//
// A message's checks table (generated into src/generated/roverlink_protocol.cpp, PROGMEM on AVR):
//
//   PAYLOAD_SIZE, PAYLOAD_MAX, offsetof(<name>_len) of the variable-length last field or NO_TAIL,
//   number of value entries (CHECK_VALUES, CHECK_FLAGS), number of range entries (CHECK_RANGE),
//   then per checked field, the value entries first (unpack() walks only those), each in spec order:
//     code                       element width in bytes | kind | check | ARRAY (constants below)
//     field index                the field's position in the spec (check_ranges()' answer)
//     offsetof(struct, field)    = its offset in the payload
//     [count]                    ARRAY: elements of a fixed array; 0: the variable-length field,
//                                whose element count is in <name>_len
//     check data                 in the field's width w, little-endian:
//                                  CHECK_RANGE   lo (w), hi (w): the spec range, for check_ranges()
//                                  CHECK_VALUES  lo (w), hi (w), n, n bitmap bytes: the values
//                                                unpack() accepts (an enum's, or 0..0x7F for ASCII
//                                                chars); n = 0: all of lo..hi, else bit i set =
//                                                lo + i is a value (hi - lo < 256)
//                                  CHECK_FLAGS   mask (w): the bits unpack() accepts
//
// Bounds are order keys, compared as unsigned integers (so a range check needs no floating-point
// code): signed values with the sign bit flipped; f32 bit patterns with the sign bit set when
// positive and every bit inverted when negative. NaN is then outside every range, and the
// generator writes a float range starting or ending at 0.0 with -0.0 at the low end and 0.0 at the
// high end, so both zeros pass as the spec's comparison does.
#ifndef ROVERLINK_CODEC_LAYOUT_H
#define ROVERLINK_CODEC_LAYOUT_H

#include <stdint.h>

#include "compiler.h"

// The structs are the wire's little-endian image: AVR, ARM Cortex-M, ESP32, x86 all are.
#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "RoverLink message structs are little-endian wire images: this target is not little-endian"
#endif
static_assert(sizeof(float) == 4, "RoverLink f32 fields need a 32-bit IEEE-754 float");

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
static const uint8_t HEADER_SIZE = 5;
static const uint8_t NO_TAIL = 0xFF;    // header byte 2: the message has no variable-length field
static const uint8_t ALL_VALID = 0xFF;  // check_ranges(): every field in range

// Fills `msg` (the struct the table describes) from `len` payload bytes. False when the length does
// not fit the message, or an element fails its CHECK_VALUES or CHECK_FLAGS (msg is then written).
bool unpack(const uint8_t* checks, const uint8_t* payload, uint8_t len, void* msg);

// Index of the first field with an element outside its CHECK_RANGE, or ALL_VALID.
uint8_t check_ranges(const uint8_t* checks, const void* msg);

// The payload of a message with a variable-length last field: the fixed part and `tail_len`
// elements (at most `tail_max`) of one byte. Returns the payload length.
uint8_t pack_tail(const void* msg, uint8_t fixed, uint8_t tail_len, uint8_t tail_max, uint8_t* payload);

}  // namespace layout
}  // namespace roverlink

#endif  // ROVERLINK_CODEC_LAYOUT_H
