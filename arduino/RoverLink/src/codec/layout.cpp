#include "layout.h"

#include <string.h>

namespace roverlink {
namespace layout {

namespace {

enum Op : uint8_t { PACK, UNPACK, CHECK };

uint8_t flash_byte(const uint8_t* p) { return ROVERLINK_READ_BYTE(p); }

// `w` little-endian bytes of check data, from flash.
uint32_t flash_le(const uint8_t* p, uint8_t w) {
    uint32_t v = 0;
    while (w-- > 0) {
        v = (v << 8) | flash_byte(p + w);
    }
    return v;
}

// One struct member of `w` bytes, through a variable of its own width (any host byte order).
uint32_t load_member(const uint8_t* m, uint8_t w) {
    if (w == 1) {
        return *m;
    }
    if (w == 2) {
        uint16_t v;
        memcpy(&v, m, sizeof v);
        return v;
    }
    uint32_t v;
    memcpy(&v, m, sizeof v);
    return v;
}

void store_member(uint8_t* m, uint8_t w, uint32_t v) {
    if (w == 1) {
        *m = static_cast<uint8_t>(v);
    } else if (w == 2) {
        const uint16_t x = static_cast<uint16_t>(v);
        memcpy(m, &x, sizeof x);
    } else {
        memcpy(m, &v, sizeof v);
    }
}

// An element's bits (zero-extended from its width w) as a number whose unsigned order is the
// order of the values, so every range check is an integer comparison. NaN maps to 0, below the
// low end of every float range (the generator never writes a NaN bound).
uint32_t order_key(uint8_t code, uint8_t w, uint32_t raw) {
    switch (code & KIND_MASK) {
    case KIND_SIGNED: {
        const uint32_t sign = 1UL << (8u * w - 1u);
        return ((raw ^ sign) - sign) ^ 0x80000000UL;  // sign-extended, then zero moved to the middle
    }
    case KIND_FLOAT:
        if ((raw << 1) > 0xFF000000UL) {
            return 0;  // NaN
        }
        if ((raw << 1) == 0) {
            return 0x80000000UL;  // -0.0 == 0.0
        }
        return (raw & 0x80000000UL) ? ~raw : (raw | 0x80000000UL);
    default:
        return raw;
    }
}

// Whether element value `v` passes the field's check (data: its check data in flash).
ROVERLINK_NOINLINE bool accepts(uint8_t code, const uint8_t* data, uint32_t v) {
    const uint8_t w = static_cast<uint8_t>(1u << (code & WIDTH_MASK));
    const uint32_t first = flash_le(data, w);
    switch (code & CHECK_MASK) {
    case CHECK_FLAGS:
        return (v & ~first) == 0;
    case CHECK_VALUE_SET: {
        const uint32_t k = v - first;  // below `first`: wraps far past the bitmap
        return k < 8u * flash_byte(data + w) && ((flash_byte(data + w + 1 + (k >> 3)) >> (k & 7u)) & 1u) != 0;
    }
    default: {  // CHECK_RANGE, CHECK_VALUES
        const uint32_t key = order_key(code, w, v);
        return key >= order_key(code, w, first) && key <= order_key(code, w, flash_le(data + w, w));
    }
    }
}

// The one walk over a layout's fields behind pack, unpack and check_ranges. PACK reads the
// struct and writes the payload, UNPACK the other way round, CHECK only reads the struct. Returns
// the index of the first field with an element that fails the operation's checks (PACK checks
// nothing), else ALL_VALID; `len` is the payload length (in for UNPACK, out for PACK).
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
            if (count == 0) {  // the variable-length last field
                count = flash_byte(p++);
                uint8_t* const used = base + flash_byte(p++);
                if (op == UNPACK) {
                    // The rest of the payload; unpack() checked len <= PAYLOAD_MAX, so it fits.
                    const uint8_t rest = static_cast<uint8_t>(len - pos);
                    count = static_cast<uint8_t>(rest >> log_w);
                    if (static_cast<uint8_t>(count << log_w) != rest) {
                        return i;  // not a whole number of elements
                    }
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
        } else if (check == CHECK_VALUE_SET) {
            p += w + 1 + flash_byte(p + w);
        } else if (check != CHECK_NONE) {
            p += 2 * w;
        }
        const bool checked = op == CHECK ? check == CHECK_RANGE : op == UNPACK && check > CHECK_RANGE;
        for (; count > 0; --count, m += w, pos = static_cast<uint8_t>(pos + w)) {
            uint32_t v = 0;
            if (op == UNPACK) {
                for (uint8_t k = w; k-- > 0;) {
                    v = (v << 8) | payload[pos + k];
                }
                store_member(m, w, v);
            } else {
                v = load_member(m, w);
                if (op == PACK) {
                    uint32_t out = v;
                    for (uint8_t k = 0; k < w; ++k, out >>= 8) {
                        payload[pos + k] = static_cast<uint8_t>(out);
                    }
                }
            }
            if (checked && !accepts(code, data, v)) {
                return i;
            }
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
