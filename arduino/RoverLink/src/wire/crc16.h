// CRC-16/CCITT-FALSE: poly 0x1021, init 0xFFFF, no reflection, xorout 0 ("123456789" -> 0x29B1).
#ifndef ROVERLINK_WIRE_CRC16_H
#define ROVERLINK_WIRE_CRC16_H

#include <stddef.h>
#include <stdint.h>

#include "compiler.h"

namespace roverlink {

static const uint16_t CRC16_INIT = 0xFFFFu;

// Table-free byte update: the shift/xor form of the polynomial,
//   x = (crc >> 8) ^ byte;  x ^= x >> 4;  crc' = (crc << 8) ^ (x << 12) ^ (x << 5) ^ x,
// split into its two result bytes so an 8-bit CPU needs only byte ops and no 512-byte table in
// flash. Forced inline: the decoder runs it for every received byte.
#if defined(__AVR__)
// On AVR, the same steps as 17 one-cycle instructions; avr-gcc spends about 22 on the C below
// (it rebuilds the 16-bit result from its bytes). The firmware-in-the-loop tests check every
// frame's CRC both ways against the Python codec.
ROVERLINK_ALWAYS_INLINE uint16_t crc16_update(uint16_t crc, uint8_t byte) {
    uint8_t t;
    __asm__(
        "eor  %[x], %B[crc]\n\t"     // x = hi ^ byte
        "mov  %[t], %[x]\n\t"
        "swap %[t]\n\t"
        "andi %[t], 0x0F\n\t"
        "eor  %[x], %[t]\n\t"        // x ^= x >> 4
        "mov  %B[crc], %A[crc]\n\t"  // hi' = lo
        "mov  %[t], %[x]\n\t"
        "swap %[t]\n\t"
        "andi %[t], 0xF0\n\t"
        "eor  %B[crc], %[t]\n\t"     // hi' ^= x << 4
        "lsl  %[t]\n\t"
        "eor  %[t], %[x]\n\t"
        "mov  %A[crc], %[t]\n\t"     // lo' = (x << 5) ^ x
        "lsr  %[x]\n\t"
        "lsr  %[x]\n\t"
        "lsr  %[x]\n\t"
        "eor  %B[crc], %[x]"           // hi' ^= x >> 3
        : [crc] "+r"(crc), [x] "+r"(byte), [t] "=&d"(t));
    return crc;
}
#else
ROVERLINK_ALWAYS_INLINE uint16_t crc16_update(uint16_t crc, uint8_t byte) {
    uint8_t x = static_cast<uint8_t>(static_cast<uint8_t>(crc >> 8) ^ byte);
    x = static_cast<uint8_t>(x ^ (x >> 4));
    const uint8_t x4 = static_cast<uint8_t>(x << 4);
    const uint8_t hi = static_cast<uint8_t>(static_cast<uint8_t>(crc) ^ x4 ^ static_cast<uint8_t>(x >> 3));
    const uint8_t lo = static_cast<uint8_t>(static_cast<uint8_t>(x4 << 1) ^ x);
    return static_cast<uint16_t>((static_cast<uint16_t>(hi) << 8) | lo);
}
#endif

// CRC over a buffer, continuing from `crc` (pass CRC16_INIT to start).
uint16_t crc16(const uint8_t* data, size_t len, uint16_t crc = CRC16_INIT);

}  // namespace roverlink

#endif  // ROVERLINK_WIRE_CRC16_H
