#include "codec.h"

namespace roverlink {

namespace {

// COBS for a body shorter than 254 bytes: body byte i lands at out[i + 1] and every zero is
// replaced by the distance to the next one, so no 0xFF blocks and no bounds checks are needed.
// Writes never pass the read position, which makes packing in place at out + 3 safe.
class BodyWriter {
public:
    explicit BodyWriter(uint8_t* out) : out_(out), pos_(0), code_pos_(0), crc_(CRC16_INIT) {}

    void put(uint8_t b) {
        crc_ = crc16_update(crc_, b);
        emit(b);
    }

    // Appends the CRC (with the unsent CRC_EXTRA mixed in) and the delimiter; returns the length.
    size_t finish(uint8_t crc_extra) {
        const uint16_t crc = crc16(&crc_extra, 1, crc_);  // a call: one inlined CRC is enough
        emit(static_cast<uint8_t>(crc & 0xFFu));
        emit(static_cast<uint8_t>(crc >> 8));
        ++pos_;
        out_[code_pos_] = static_cast<uint8_t>(pos_ - code_pos_);
        out_[pos_] = 0;
        return static_cast<size_t>(pos_) + 1u;
    }

private:
    ROVERLINK_ALWAYS_INLINE void emit(uint8_t b) {
        ++pos_;
        if (b == 0) {
            out_[code_pos_] = static_cast<uint8_t>(pos_ - code_pos_);
            code_pos_ = pos_;
        } else {
            out_[pos_] = b;
        }
    }

    uint8_t* out_;
    uint8_t pos_;       // index of the last byte written
    uint8_t code_pos_;  // index of the open block's code byte
    uint16_t crc_;
};

}  // namespace

size_t encode_frame(uint8_t msg_id, uint8_t seq, uint8_t crc_extra, const uint8_t* payload,
                    uint8_t len, uint8_t* out, size_t cap) {
    if (len > proto::MAX_PAYLOAD || out == 0 || cap < frame_size(len) || (len != 0 && payload == 0)) {
        return 0;
    }
    BodyWriter w(out);
    w.put(msg_id);
    w.put(seq);
    for (uint8_t i = 0; i < len; ++i) {
        w.put(payload[i]);
    }
    return w.finish(crc_extra);
}

}  // namespace roverlink
