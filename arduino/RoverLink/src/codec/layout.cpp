#include "layout.h"

#include <string.h>

namespace roverlink {
namespace layout {

namespace {

uint8_t flash_byte(const uint8_t* p) { return ROVERLINK_READ_BYTE(p); }

// An element's order key (w bytes, little-endian): signed with the sign bit flipped; f32 (sign
// and magnitude) with the sign bit set when positive, every bit inverted when negative. The keys'
// unsigned order is the numbers' order, so a NaN comes out beyond -inf or +inf and fails every
// range; the generator writes the bounds as keys.
void to_key(uint8_t code, const uint8_t* value, uint8_t w, uint8_t* k) {
    const uint8_t kind = code & KIND_MASK;
    const uint8_t invert = kind == KIND_FLOAT && (value[w - 1] & 0x80) ? 0xFF : 0x00;
    for (uint8_t i = 0; i < w; ++i) {
        k[i] = value[i] ^ invert;
    }
    if (kind != KIND_UNSIGNED && invert == 0) {
        k[w - 1] ^= 0x80;
    }
}

// Compares a key (RAM) with a bound (flash), both w bytes little-endian: < 0, 0, > 0.
int8_t compare(const uint8_t* k, const uint8_t* bound, uint8_t w) {
    for (uint8_t i = w; i-- > 0;) {
        const uint8_t b = flash_byte(bound + i);
        if (k[i] != b) {
            return k[i] < b ? -1 : 1;
        }
    }
    return 0;
}

// The field index of the first element that fails a check of the wanted kind (CHECK_RANGE, or the
// value checks when `ranges` is false), else ALL_VALID.
uint8_t first_failing(const uint8_t* checks, const uint8_t* m, bool ranges) {
    const uint8_t* p = checks + HEADER_SIZE;
    for (uint8_t n = flash_byte(checks + 3); n > 0; --n) {
        const uint8_t code = flash_byte(p);
        const uint8_t field = flash_byte(p + 1);
        const uint8_t* v = m + flash_byte(p + 2);
        p += 3;
        uint8_t count = 1;
        if (code & ARRAY) {
            count = flash_byte(p++);
            if (count == 0) {
                count = m[flash_byte(checks + 2)];  // the variable-length field: <name>_len elements
            }
        }
        const uint8_t w = code & WIDTH_MASK;
        const uint8_t check = code & CHECK_MASK;
        const uint8_t* const lo = p;
        p += check == CHECK_FLAGS ? w : 2 * w;
        const uint8_t* const bitmap = p;
        if (check == CHECK_VALUES) {
            p += 1 + flash_byte(p);  // the bitmap's size, and the bitmap
        }
        if ((check == CHECK_RANGE) != ranges) {
            continue;
        }
        for (; count > 0; --count, v += w) {
            uint8_t k[4];
            to_key(code, v, w, k);
            bool ok = true;
            if (check == CHECK_FLAGS) {
                for (uint8_t i = 0; i < w; ++i) {
                    ok = ok && (k[i] & ~flash_byte(lo + i)) == 0;
                }
            } else {
                ok = compare(k, lo, w) >= 0 && compare(k, lo + w, w) <= 0;
                // CHECK_VALUES with a bitmap: hi - lo < 256, so the low bytes' difference is the bit.
                if (ok && check == CHECK_VALUES && flash_byte(bitmap) != 0) {
                    const uint8_t i = static_cast<uint8_t>(k[0] - flash_byte(lo));
                    ok = (flash_byte(bitmap + 1 + (i >> 3)) >> (i & 7u)) & 1u;
                }
            }
            if (!ok) {
                return field;
            }
        }
    }
    return ALL_VALID;
}

}  // namespace

bool unpack(const uint8_t* checks, const uint8_t* payload, uint8_t len, void* msg) {
    const uint8_t fixed = flash_byte(checks);
    if (len < fixed || len > flash_byte(checks + 1)) {
        return false;
    }
    uint8_t* const m = static_cast<uint8_t*>(msg);
    memcpy(m, payload, len);
    const uint8_t tail = flash_byte(checks + 2);
    if (tail != NO_TAIL) {
        m[tail] = static_cast<uint8_t>(len - fixed);
    }
    return first_failing(checks, m, false) == ALL_VALID;
}

uint8_t check_ranges(const uint8_t* checks, const void* msg) {
    return first_failing(checks, static_cast<const uint8_t*>(msg), true);
}

uint8_t pack_tail(const void* msg, uint8_t fixed, uint8_t tail_len, uint8_t tail_max, uint8_t* payload) {
    const uint8_t len = static_cast<uint8_t>(fixed + (tail_len < tail_max ? tail_len : tail_max));
    memcpy(payload, msg, len);
    return len;
}

}  // namespace layout
}  // namespace roverlink
