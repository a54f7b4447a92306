#include "cobs.h"

namespace roverlink {

size_t cobs_encode(const uint8_t* in, size_t len, uint8_t* out, size_t cap) {
    if (cap == 0) {
        return 0;
    }
    size_t code_pos = 0;  // where the current block's code byte goes
    size_t pos = 1;
    uint8_t code = 1;     // 1 + data bytes in the current block
    for (size_t i = 0; i < len; ++i) {
        const uint8_t b = in[i];
        if (b != 0) {
            if (pos >= cap) {
                return 0;
            }
            out[pos++] = b;
            ++code;
        }
        // A zero ends the block; so does a full 254-byte run, but then only if more input follows
        // (a final 0xFF block needs no trailing code byte).
        if (b == 0 || (code == 0xFF && i + 1 < len)) {
            if (pos >= cap) {
                return 0;
            }
            out[code_pos] = code;
            code_pos = pos++;
            code = 1;
        }
    }
    out[code_pos] = code;
    return pos;
}

bool cobs_decode(const uint8_t* in, size_t len, uint8_t* out, size_t cap, size_t& out_len) {
    if (len == 0) {
        return false;
    }
    size_t i = 0;
    size_t o = 0;
    while (i < len) {
        const uint8_t code = in[i++];
        if (code == 0) {
            return false;
        }
        const size_t n = static_cast<size_t>(code - 1u);
        if (n > len - i || n > cap - o) {
            return false;
        }
        for (size_t k = 0; k < n; ++k) {
            const uint8_t b = in[i++];
            if (b == 0) {
                return false;
            }
            out[o++] = b;
        }
        // Every block but a full one implies a zero, except the last block's (the implicit end).
        if (code != 0xFF && i < len) {
            if (o >= cap) {
                return false;
            }
            out[o++] = 0;
        }
    }
    out_len = o;
    return true;
}

}  // namespace roverlink
