#include "layout.h"

#include <string.h>

namespace roverlink {
namespace layout {

namespace {

enum Op : uint8_t { PACK, UNPACK, CHECK };

uint8_t flash_byte(const uint8_t* p) { return ROVERLINK_READ_BYTE(p); }

// A struct member <-> its w bytes little-endian: through a variable of the member's own width
// and shifts, so the wire is the same whatever the host's byte order.
void member_to_le(const uint8_t* m, uint8_t* le, uint8_t w) {
    uint32_t v;
    if (w == 1) {
        v = *m;
    } else if (w == 2) {
        uint16_t x;
        memcpy(&x, m, sizeof x);
        v = x;
    } else {
        memcpy(&v, m, sizeof v);
    }
    for (uint8_t i = 0; i < w; ++i, v >>= 8) {
        le[i] = static_cast<uint8_t>(v);
    }
}

void le_to_member(const uint8_t* le, uint8_t* m, uint8_t w) {
    uint32_t v = 0;
    for (uint8_t i = w; i-- > 0;) {
        v = (v << 8) | le[i];
    }
    if (w == 1) {
        *m = static_cast<uint8_t>(v);
    } else if (w == 2) {
        const uint16_t x = static_cast<uint16_t>(v);
        memcpy(m, &x, sizeof x);
    } else {
        memcpy(m, &v, sizeof v);
    }
}

// Compares value (w bytes little-endian, RAM) with bound (the same, in flash) as numbers of the
// field's kind: < 0, 0, > 0. Both are read from the top byte down as keys whose unsigned order is
// the numbers' order: signed: the sign bit flipped; f32 (sign and magnitude): a positive number
// gets its sign bit set, a negative one has every bit inverted. NaNs come out beyond -inf and
// +inf, so they fail every range.
int8_t compare(uint8_t code, const uint8_t* value, const uint8_t* bound) {
    const uint8_t w = code & WIDTH_MASK;
    uint8_t flip_v = 0;  // XORed into the lower bytes: 0xFF for a negative f32
    uint8_t flip_b = 0;
    for (uint8_t i = w; i-- > 0;) {
        uint8_t v = value[i] ^ flip_v;
        uint8_t b = flash_byte(bound + i) ^ flip_b;
        if (i == w - 1u && (code & KIND_MASK) != KIND_UNSIGNED) {
            if (code & KIND_FLOAT) {
                flip_v = (v & 0x80) ? 0xFF : 0x00;
                flip_b = (b & 0x80) ? 0xFF : 0x00;
            }
            v ^= flip_v | 0x80;
            b ^= flip_b | 0x80;
        }
        if (v != b) {
            return v < b ? -1 : 1;
        }
    }
    return 0;
}

// Whether an element (w bytes little-endian) passes its field's check; data: the check data.
bool accepts(uint8_t code, const uint8_t* data, const uint8_t* value) {
    const uint8_t w = code & WIDTH_MASK;
    if ((code & CHECK_MASK) == CHECK_FLAGS) {
        for (uint8_t i = 0; i < w; ++i) {
            if (value[i] & ~flash_byte(data + i)) {
                return false;
            }
        }
        return true;
    }
    if (compare(code, value, data) < 0 || compare(code, value, data + w) > 0) {
        return false;
    }
    // CHECK_VALUES with a bitmap: lo <= value <= hi and hi - lo < 256, so the low bytes' difference
    // is the value's bit.
    const uint8_t* bitmap = data + 2 * w;
    if ((code & CHECK_MASK) == CHECK_VALUES && flash_byte(bitmap) != 0) {
        const uint8_t k = static_cast<uint8_t>(value[0] - flash_byte(data));
        return (flash_byte(bitmap + 1 + (k >> 3)) >> (k & 7u)) & 1u;
    }
    return true;
}

uint8_t walk(Op op, const uint8_t* layout, uint8_t* base, uint8_t* payload, uint8_t& len) {
    const uint8_t* p = layout + HEADER_SIZE;
    const uint8_t fields = flash_byte(layout + 2);
    uint8_t pos = 0;
    for (uint8_t i = 0; i < fields; ++i) {
        const uint8_t code = flash_byte(p);
        uint8_t* m = base + flash_byte(p + 1);
        p += 2;
        const uint8_t w = code & WIDTH_MASK;
        uint8_t count = 1;
        if (code & ARRAY) {
            count = flash_byte(p++);
            if (count == 0) {  // the variable-length last field (bytes): max_len, offsetof(len)
                count = flash_byte(p);
                uint8_t* const used = base + flash_byte(p + 1);
                p += 2;
                if (op == UNPACK) {
                    count = static_cast<uint8_t>(len - pos);  // unpack() checked len <= PAYLOAD_MAX
                    *used = count;
                } else if (*used < count) {
                    count = *used;
                }
            }
        }
        const uint8_t check = code & CHECK_MASK;
        const uint8_t* const data = p;
        if (check == CHECK_FLAGS) {
            p += w;
        } else if (check != CHECK_NONE) {
            p += 2 * w;
            if (check == CHECK_VALUES) {
                p += 1 + flash_byte(p);  // the bitmap's size, and the bitmap
            }
        }
        const bool checked = op == CHECK ? check == CHECK_RANGE : op == UNPACK && check > CHECK_RANGE;
        for (; count > 0; --count, m += w) {
            uint8_t scratch[4];
            uint8_t* const wire = op == CHECK ? scratch : payload + pos;
            if (op == UNPACK) {
                le_to_member(wire, m, w);
            } else {
                member_to_le(m, wire, w);
            }
            if (checked && !accepts(code, data, wire)) {
                return i;
            }
            pos = static_cast<uint8_t>(pos + w);
        }
    }
    len = pos;
    return ALL_VALID;
}

}  // namespace

// walk() takes one mutable struct pointer and one mutable payload pointer for all three
// operations; it writes only the struct in UNPACK and only the payload in PACK.
uint8_t pack(const uint8_t* layout, const void* msg, uint8_t* payload) {
    uint8_t len = 0;
    walk(PACK, layout, const_cast<uint8_t*>(static_cast<const uint8_t*>(msg)), payload, len);
    return len;
}

bool unpack(const uint8_t* layout, const uint8_t* payload, uint8_t len, void* msg) {
    if (len < flash_byte(layout) || len > flash_byte(layout + 1)) {
        return false;
    }
    return walk(UNPACK, layout, static_cast<uint8_t*>(msg), const_cast<uint8_t*>(payload), len) == ALL_VALID;
}

uint8_t check_ranges(const uint8_t* layout, const void* msg) {
    uint8_t len = 0;
    return walk(CHECK, layout, const_cast<uint8_t*>(static_cast<const uint8_t*>(msg)), 0, len);
}

}  // namespace layout
}  // namespace roverlink
