// Frame encoder: body = msg_id | seq | payload | crc16 LE, written as COBS(body) + 0x00.
#ifndef ROVERLINK_CODEC_FRAME_ENCODER_H
#define ROVERLINK_CODEC_FRAME_ENCODER_H

#include <stddef.h>
#include <stdint.h>

#include "../generated/roverlink_protocol.h"

namespace roverlink {

// COBS code byte + msg_id + seq + crc (2) + delimiter. Exact, because a body never reaches
// 254 bytes (checked in codec.h), so COBS adds exactly one byte.
static const uint8_t FRAME_OVERHEAD = 6;

// Wire size of a frame carrying `payload_len` bytes.
inline size_t frame_size(uint8_t payload_len) {
    return static_cast<size_t>(payload_len) + FRAME_OVERHEAD;
}

// Writes one complete frame (including the trailing 0x00) into `out`. Returns its length, or 0
// when len > MAX_PAYLOAD or cap < frame_size(len). The payload is first moved to `out + 3`, its own
// slot in the frame (it may overlap `out`); a message packed there already is encoded in place,
// with no second buffer.
size_t encode_frame(uint8_t msg_id, uint8_t seq, uint8_t crc_extra, const uint8_t* payload,
                    uint8_t len, uint8_t* out, size_t cap);

// Packs and frames a generated message. `cap` must hold the frame for M::PAYLOAD_MAX
// (frame_size(M::PAYLOAD_MAX); proto::MAX_FRAME always does), else returns 0.
template <class M>
size_t encode_message(const M& m, uint8_t seq, uint8_t* out, size_t cap) {
    static_assert(M::PAYLOAD_MAX <= proto::MAX_PAYLOAD, "message payload exceeds MAX_PAYLOAD");
    if (out == 0 || cap < frame_size(M::PAYLOAD_MAX)) {
        return 0;
    }
    // Pack straight into the payload slot; saves a MAX_PAYLOAD stack buffer on AVR.
    uint8_t* const slot = out + 3;
    const uint8_t len = proto::pack(m, slot);
    return encode_frame(M::ID, seq, M::CRC_EXTRA, len != 0 ? slot : 0, len, out, cap);  // 0: nothing to read
}

}  // namespace roverlink

#endif  // ROVERLINK_CODEC_FRAME_ENCODER_H
