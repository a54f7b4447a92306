#include "codec.h"

namespace roverlink {

namespace {
// Longest encoded chunk (without its delimiter) that can still be a frame: a MAX_BODY body
// encodes to MAX_BODY + 1 bytes (one COBS block). Capping here means body_ can never overflow.
const uint8_t MAX_CHUNK = static_cast<uint8_t>(proto::MAX_BODY + 1u);
// chunk_len_ value while an over-long chunk is dropped up to the next delimiter.
const uint8_t SKIPPING = 0xFF;
static_assert(MAX_CHUNK < SKIPPING, "SKIPPING must not be a real chunk length");
static_assert(MAX_CHUNK < 255, "a 0xFF COBS block (code + 254 bytes) must not fit in a chunk");

// Out of line: a 32-bit increment inlined at every counter costs ~20 bytes of AVR flash each.
ROVERLINK_NOINLINE void bump(uint32_t& counter) { ++counter; }
}  // namespace

FrameDecoder::FrameDecoder() : payload_len_(0), frame_chunk_len_(0) {
    for (uint8_t i = 0; i < proto::MAX_BODY; ++i) {
        body_[i] = 0;
    }
    reset();
    reset_stats();
}

void FrameDecoder::reset() {
    chunk_len_ = 0;
    remaining_ = 0;
    body_len_ = 0;
    crc_ = CRC16_INIT;
}

void FrameDecoder::reset_stats() {
    stats_.frames_ok = 0;
    stats_.crc_errors = 0;
    stats_.cobs_errors = 0;
    stats_.length_errors = 0;
    stats_.unknown_ids = 0;
    stats_.value_errors = 0;
    stats_.bytes_discarded = 0;
}

ROVERLINK_ALWAYS_INLINE void FrameDecoder::append(uint8_t b) {
    const uint8_t n = body_len_;
    if (n >= 2) {
        crc_ = crc16_update(crc_, body_[n - 2]);
    }
    body_[n] = b;
    body_len_ = static_cast<uint8_t>(n + 1u);
}

// Per-byte hot path: kept free of calls so avr-gcc needs no register saves for it.
FrameDecoder::Result FrameDecoder::push(uint8_t byte) {
    if (byte == 0) {
        return finish_chunk();
    }
    if (chunk_len_ >= MAX_CHUNK) {
        return drop_byte();
    }
    ++chunk_len_;
    if (remaining_ != 0) {  // data byte: the common case
        --remaining_;
    } else {
        // A code byte. The previous block's implied zero is only real now that another block
        // follows, so it is stored now (the last block's is dropped). A full 0xFF block, the
        // one kind without an implied zero, cannot fit in MAX_CHUNK, so needs no case here.
        const bool implied_zero = chunk_len_ > 1;
        remaining_ = static_cast<uint8_t>(byte - 1u);
        if (!implied_zero) {
            return NONE;
        }
        byte = 0;
    }
    append(byte);  // one call site: the inlined CRC exists once in flash
    return NONE;
}

FrameDecoder::Result FrameDecoder::drop_byte() {
    if (chunk_len_ == SKIPPING) {
        bump(stats_.bytes_discarded);
        return NONE;
    }
    stats_.bytes_discarded += static_cast<uint32_t>(chunk_len_) + 1u;
    bump(stats_.cobs_errors);
    reset();
    chunk_len_ = SKIPPING;
    return ERR_OVERLONG;
}

void FrameDecoder::reject_payload() {
    if (frame_chunk_len_ == 0) {
        return;  // no FRAME to take back (called twice, or before any frame)
    }
    --stats_.frames_ok;
    bump(stats_.value_errors);
    stats_.bytes_discarded += frame_chunk_len_;
    frame_chunk_len_ = 0;
}

FrameDecoder::Result FrameDecoder::finish_chunk() {
    const uint8_t chunk_len = chunk_len_;
    if (chunk_len == 0 || chunk_len == SKIPPING) {  // empty, or an over-long one already counted
        reset();
        return NONE;
    }
    Result r;
    proto::MessageBounds bounds;
    const uint8_t n = body_len_;
    if (remaining_ != 0) {  // chunk ended inside a COBS block
        bump(stats_.cobs_errors);
        r = ERR_COBS;
    } else if (n < 4) {
        bump(stats_.length_errors);
        r = ERR_LENGTH;
    } else if (!proto::message_bounds(body_[0], bounds)) {
        bump(stats_.unknown_ids);
        r = ERR_UNKNOWN_ID;
    } else if (crc16(&bounds.crc_extra, 1, crc_) !=  // a call: once per frame
               static_cast<uint16_t>(body_[n - 2] | (body_[n - 1] << 8))) {
        bump(stats_.crc_errors);
        r = ERR_CRC;
    } else if (n - 4u < bounds.min_payload || n - 4u > bounds.max_payload) {
        bump(stats_.length_errors);
        r = ERR_LENGTH;
    } else {
        payload_len_ = static_cast<uint8_t>(n - 4u);
        frame_chunk_len_ = chunk_len;
        bump(stats_.frames_ok);
        reset();
        return FRAME;
    }
    stats_.bytes_discarded += chunk_len;
    reset();
    return r;
}

}  // namespace roverlink
