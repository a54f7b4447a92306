#include "layout.h"

#include <string.h>

namespace roverlink {
namespace layout {

bool copy_payload(const uint8_t* payload, uint8_t len, uint8_t min, uint8_t max, void* msg) {
    if (len < min || len > max) {
        return false;
    }
    uint8_t* const m = static_cast<uint8_t*>(msg);
    if (len != 0) {  // an empty payload's pointer may be null
        memcpy(m, payload, len);
    }
    if (min != max) {
        m[max] = static_cast<uint8_t>(len - min);
    }
    return true;
}

bool f32_within(float v, uint32_t lo_key, uint32_t hi_key) {
    uint32_t key;
    memcpy(&key, &v, sizeof key);
    key = (key & 0x80000000UL) ? ~key : (key | 0x80000000UL);
    return key >= lo_key && key <= hi_key;
}

uint8_t pack_tail(const void* msg, uint8_t fixed, uint8_t tail_len, uint8_t tail_max, uint8_t* payload) {
    const uint8_t len = static_cast<uint8_t>(fixed + (tail_len < tail_max ? tail_len : tail_max));
    memcpy(payload, msg, len);
    return len;
}

}  // namespace layout
}  // namespace roverlink
