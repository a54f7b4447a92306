#include "layout.h"

#include <string.h>

namespace roverlink {
namespace layout {

namespace {

uint8_t flash_byte(const uint8_t* p) { return ROVERLINK_READ_BYTE(p); }

// Compares an element (w bytes little-endian, RAM) with a bound (flash) as numbers of the field's
// kind: < 0, 0, > 0. The bound is an order key (layout.h); the element's key is made byte by byte
// from the top down, so most comparisons end at the first byte: signed: the sign bit flipped; f32
// (sign and magnitude): the sign bit set when positive, every bit inverted when negative. NaNs come
// out beyond -inf and +inf, so they fail every range.
int8_t compare(uint8_t code, const uint8_t* v, const uint8_t* bound, uint8_t w) {
    const uint8_t kind = code & KIND_MASK;
    const uint8_t invert = kind == KIND_FLOAT && (v[w - 1] & 0x80) ? 0xFF : 0x00;
    uint8_t flip = kind != KIND_UNSIGNED && invert == 0 ? 0x80 : 0x00;  // the top byte's sign bit
    for (uint8_t i = w; i-- > 0; flip = 0) {
        const uint8_t k = static_cast<uint8_t>(v[i] ^ invert ^ flip);
        const uint8_t b = flash_byte(bound + i);
        if (k != b) {
            return k < b ? -1 : 1;
        }
    }
    return 0;
}

// Whether an element passes its field's check; data: the check data (layout.h).
bool accepts(uint8_t code, const uint8_t* data, const uint8_t* v) {
    const uint8_t w = code & WIDTH_MASK;
    const uint8_t check = code & CHECK_MASK;
    if (check == CHECK_FLAGS) {
        for (uint8_t i = 0; i < w; ++i) {
            if (v[i] & ~flash_byte(data + i)) {
                return false;
            }
        }
        return true;
    }
    if (compare(code, v, data, w) < 0 || compare(code, v, data + w, w) > 0) {
        return false;
    }
    // CHECK_VALUES with a bitmap: lo <= value <= hi and hi - lo < 256, so the low bytes' difference
    // (of the keys: the values of an enum, never floats) is the value's bit.
    const uint8_t* const bitmap = data + 2 * w;
    if (check == CHECK_VALUES && flash_byte(bitmap) != 0) {
        const uint8_t low = w == 1 && (code & KIND_MASK) == KIND_SIGNED ? v[0] ^ 0x80 : v[0];
        const uint8_t k = static_cast<uint8_t>(low - flash_byte(data));
        return (flash_byte(bitmap + 1 + (k >> 3)) >> (k & 7u)) & 1u;
    }
    return true;
}

// The field index of the first element that fails a check of the wanted kind (the range entries,
// or the value entries before them), else ALL_VALID.
uint8_t first_failing(const uint8_t* checks, const uint8_t* m, bool ranges) {
    const uint8_t values = flash_byte(checks + 3);
    const uint8_t first = ranges ? values : 0;
    const uint8_t end = ranges ? static_cast<uint8_t>(values + flash_byte(checks + 4)) : values;
    const uint8_t* p = checks + HEADER_SIZE;
    for (uint8_t e = 0; e < end; ++e) {
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
        const uint8_t* const data = p;
        p += check == CHECK_FLAGS ? w : 2 * w;
        if (check == CHECK_VALUES) {
            p += 1 + flash_byte(p);  // the bitmap's size, and the bitmap
        }
        if (e < first) {
            continue;
        }
        for (; count > 0; --count, v += w) {
            if (!accepts(code, data, v)) {
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
