// Packed structs, inlining hints and flash access: message structs are packed wire images; the hot
// per-byte path wants inlining forced, rare paths want it prevented, because avr-gcc -Os decides the
// other way round in both cases; constant tables live in flash (PROGMEM) on AVR, where reading them
// takes pgm_read_byte() / pgm_read_word().
#ifndef ROVERLINK_WIRE_COMPILER_H
#define ROVERLINK_WIRE_COMPILER_H

// ROVERLINK_OUT_OF_LINE also keeps GCC from cloning the function for a constant argument (with
// LTO, a copy for the one global object, whose members it then addresses absolutely: four bytes
// per access on AVR instead of two through the pointer).
#if defined(__clang__)  // the native builds' other compiler (tests/firmware/fuzz): it has no noclone
#define ROVERLINK_ALWAYS_INLINE inline __attribute__((always_inline))
#define ROVERLINK_NOINLINE __attribute__((noinline))
#define ROVERLINK_OUT_OF_LINE __attribute__((noinline))
#define ROVERLINK_PACKED __attribute__((packed))
#elif defined(__GNUC__)
#define ROVERLINK_ALWAYS_INLINE inline __attribute__((always_inline))
#define ROVERLINK_NOINLINE __attribute__((noinline))
#define ROVERLINK_OUT_OF_LINE __attribute__((noinline, noclone))
#define ROVERLINK_PACKED __attribute__((packed))
#else
#define ROVERLINK_ALWAYS_INLINE inline
#define ROVERLINK_NOINLINE
#define ROVERLINK_OUT_OF_LINE
#error "RoverLink's message structs need GCC's or Clang's packed attribute"
#endif

#if defined(__AVR__)
#include <avr/pgmspace.h>
#define ROVERLINK_PROGMEM PROGMEM
#define ROVERLINK_READ_BYTE(p) pgm_read_byte(p)
#define ROVERLINK_READ_PTR(p) reinterpret_cast<const uint8_t*>(pgm_read_word(p))  // a const uint8_t*
#else
#define ROVERLINK_PROGMEM
#define ROVERLINK_READ_BYTE(p) (*(p))
#define ROVERLINK_READ_PTR(p) (*(p))
#endif

#endif  // ROVERLINK_WIRE_COMPILER_H
