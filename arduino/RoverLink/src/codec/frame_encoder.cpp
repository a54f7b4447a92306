#include "codec.h"

#include <string.h>

namespace roverlink {

size_t encode_frame(uint8_t msg_id, uint8_t seq, uint8_t crc_extra, const uint8_t* payload,
                    uint8_t len, uint8_t* out, size_t cap) {
    if (len > proto::MAX_PAYLOAD || out == 0 || cap < frame_size(len) || (len != 0 && payload == 0)) {
        return 0;
    }
    // The body (msg_id, seq, payload, crc) goes to out[1..n], then COBS turns it into the frame in
    // place: each zero becomes the distance to the next one, out[0] the distance to the first. A
    // body is shorter than 254 bytes (codec.h), so there is exactly one code byte per zero.
    if (len != 0 && payload != out + 3) {
        memmove(out + 3, payload, len);
    }
    out[1] = msg_id;
    out[2] = seq;
    const uint8_t n = static_cast<uint8_t>(len + 4u);
    out[n - 1] = crc_extra;  // hashed after the body, never sent: the CRC overwrites it
    const uint16_t crc = crc16(out + 1, static_cast<uint8_t>(n - 1u));
    out[n - 1] = static_cast<uint8_t>(crc);
    out[n] = static_cast<uint8_t>(crc >> 8);
    uint8_t code = 0;  // where the open block's code byte goes
    for (uint8_t i = 1; i <= n; ++i) {
        if (out[i] == 0) {
            out[code] = static_cast<uint8_t>(i - code);
            code = i;
        }
    }
    out[code] = static_cast<uint8_t>(n + 1u - code);
    out[n + 1] = 0;
    return static_cast<size_t>(n) + 2u;
}

}  // namespace roverlink
