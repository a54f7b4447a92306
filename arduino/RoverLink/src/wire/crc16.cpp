#include "crc16.h"

namespace roverlink {

uint16_t crc16(const uint8_t* data, size_t len, uint16_t crc) {
    if (len != 0) {
        // Test at the bottom: one compare and branch per byte, where avr-gcc -Os gives the
        // `for` form two jumps.
        const uint8_t* const end = data + len;
        do {
            crc = crc16_update(crc, *data++);
        } while (data != end);
    }
    return crc;
}

}  // namespace roverlink
