// Message layouts. Every generated message struct is the little-endian wire image of its payload
// (packed, members in spec order with their wire widths, offsets static_asserted by the generator),
// so pack() and unpack() are a copy. What remains per message is generated code: values_defined()
// (enums, flag bits, ASCII) and check_ranges() (the spec ranges). This header holds the few helpers
// that code shares.
//
// Float ranges are compared as order keys, unsigned integers whose order is the numbers' order (so
// a range check needs no floating-point code): the f32 bit pattern with the sign bit set when
// positive, every bit inverted when negative. NaNs come out beyond -inf and +inf, so they fail every
// range, and the generator writes a float range starting or ending at 0.0 with -0.0 at the low end
// and 0.0 at the high end, so both zeros pass as the spec's comparison does.
#ifndef ROVERLINK_WIRE_LAYOUT_H
#define ROVERLINK_WIRE_LAYOUT_H

#include <stdint.h>

#include "compiler.h"

// The structs are the wire's little-endian image: AVR, ARM Cortex-M, ESP32, x86 all are.
#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "RoverLink message structs are little-endian wire images: this target is not little-endian"
#endif
static_assert(sizeof(float) == 4, "RoverLink f32 fields need a 32-bit IEEE-754 float");

namespace roverlink {
namespace layout {

// Copies a payload of min..max bytes into `msg`, the struct that is its image. A message with a
// variable-length last field (min < max) keeps that field's element count right after the image,
// at offset max (the generator static_asserts it). False, with `msg` untouched, for a length
// outside min..max.
bool copy_payload(const uint8_t* payload, uint8_t len, uint8_t min, uint8_t max, void* msg);

// Whether lo_key <= key(v) <= hi_key, key being the order key above.
bool f32_within(float v, uint32_t lo_key, uint32_t hi_key);

// The payload of a message with a variable-length last field: the fixed part and `tail_len`
// elements (at most `tail_max`) of one byte. Returns the payload length.
uint8_t pack_tail(const void* msg, uint8_t fixed, uint8_t tail_len, uint8_t tail_max, uint8_t* payload);

}  // namespace layout
}  // namespace roverlink

#endif  // ROVERLINK_WIRE_LAYOUT_H
