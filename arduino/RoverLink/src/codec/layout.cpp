#include "layout.h"

#include <string.h>

namespace roverlink {
namespace layout {

namespace {

enum Op : uint8_t { PACK, UNPACK, CHECK };

uint8_t flash_byte(const uint8_t* p) { return ROVERLINK_READ_BYTE(p); }

// Struct member <-> its w bytes little-endian, through a variable of the member's width and
// shifts, so the wire is the same whatever the host's byte order.
void member_to_le(const uint8_t* m, uint8_t w, uint8_t* le) {
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

void le_to_member(const uint8_t* le, uint8_t w, uint8_t* m) {
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

// Compares a value (w bytes little-endian, RAM) with a bound (the same, in flash) as numbers of
// the field's kind: < 0, 0 or > 0. Both are mapped, from the top byte down, to keys whose
// unsigned order is the numbers' order: signed: the sign bit flipped; f32 (sign and magnitude):
// a positive value gets its sign bit set, a negative one has every bit inverted.
int8_t compare(uint8_t code, const uint8_t* value, const uint8_t* bound, uint8_t w) {
    const uint8_t kind = code & KIND_MASK;
    uint8_t flip_v = 0;  // what the lower bytes are XORed with (f32: 0xFF when negative)
    uint8_t flip_b = 0;
    for (uint8_t i = w; i-- > 0;) {
        uint8_t v = value[i] ^ flip_v;
        uint8_t b = flash_byte(bound + i) ^ flip_b;
        if (i == w - 1u && kind != KIND_UNSIGNED) {
            if (kind == KIND_FLOAT) {
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

// Whether an element (w bytes little-endian) passes its field's check (data: in flash).
bool accepts(uint8_t code, const uint8_t* data, uint8_t* value) {
    const uint8_t w = static_cast<uint8_t>(1u << (code & WIDTH_MASK));
    const uint8_t check = code & CHECK_MASK;
    if (check == CHECK_FLAGS) {
        for (uint8_t i = 0; i < w; ++i) {
            if (value[i] & ~flash_byte(data + i)) {
                return false;
            }
        }
        return true;
    }
    if ((code & KIND_MASK) == KIND_FLOAT) {
        const uint8_t top = value[3] & 0x7F;
        if (top == 0x7F && (value[2] & 0x80) && ((value[2] & 0x7F) | value[1] | value[0])) {
            return false;  // NaN: outside every range
        }
        if ((top | value[2] | value[1] | value[0]) == 0) {
            value[3] = 0;  // -0.0 == 0.0
        }
    }
    if (compare(code, value, data, w) < 0 || compare(code, value, data + w, w) > 0) {
        return false;
    }
    if (check == CHECK_VALUE_SET) {  // lo <= value <= hi, hi - lo < 256: the low bytes give the bit
        const uint8_t k = static_cast<uint8_t>(value[0] - flash_byte(data));
        return ((flash_byte(data + 2 * w + (k >> 3)) >> (k & 7u)) & 1u) != 0;
    }
    return true;
}

uint8_t check_size(uint8_t code, const uint8_t* data) {
    const uint8_t w = static_cast<uint8_t>(1u << (code & WIDTH_MASK));
    switch (code & CHECK_MASK) {
    case CHECK_NONE:
        return 0;
    case CHECK_FLAGS:
        return w;
    case CHECK_VALUE_SET:  // lo, hi, then the bitmap's (hi - lo) / 8 + 1 bytes
        return static_cast<uint8_t>(2 * w + (static_cast<uint8_t>(flash_byte(data + w) - flash_byte(data)) >> 3) + 1);
    default:
        return static_cast<uint8_t>(2 * w);
    }
}

uint8_t walk(Op op, const uint8_t* layout, uint8_t* base, uint8_t* payload, uint8_t& len) {
    const uint8_t* p = layout + HEADER_SIZE;
    const uint8_t fields = flash_byte(layout + 2);
    uint8_t pos = 0;
    for (uint8_t i = 0; i < fields; ++i) {
        const uint8_t code = flash_byte(p++);
        uint8_t* m = base + flash_byte(p++);
        const uint8_t log_w = code & WIDTH_MASK;
        const uint8_t w = static_cast<uint8_t>(1u << log_w);
        uint8_t count = 1;
        if (code & ARRAY) {
            count = flash_byte(p++);
            if (count == 0) {
                count = flash_byte(p++);
                uint8_t* const used = base + flash_byte(p++);
                if (op == UNPACK) {
                    const uint8_t rest = static_cast<uint8_t>(len - pos);
                    count = static_cast<uint8_t>(rest >> log_w);
                    if (static_cast<uint8_t>(count << log_w) != rest) {
                        return i;
                    }
                    *used = count;
                } else if (*used < count) {
                    count = *used;
                }
            }
        }
        const uint8_t check = code & CHECK_MASK;
        const uint8_t* const data = p;
        p += check_size(code, p);
        const bool checked = op == CHECK ? check == CHECK_RANGE : op == UNPACK && check > CHECK_RANGE;
        for (; count > 0; --count, m += w) {
            uint8_t scratch[4];
            uint8_t* const wire = op == CHECK ? scratch : payload + pos;
            if (op == UNPACK) {
                le_to_member(wire, w, m);
            } else {
                member_to_le(m, w, wire);
            }
            if (checked && !accepts(code, data, wire)) {
                return i;
            }
            if (op != CHECK) {
                pos = static_cast<uint8_t>(pos + w);
            }
        }
    }
    len = pos;
    return ALL_VALID;
}

}  // namespace

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
