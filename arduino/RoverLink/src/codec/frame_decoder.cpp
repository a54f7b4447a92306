#include "codec.h"

#include <string.h>

namespace roverlink {

namespace {
// Longest encoded chunk (without its delimiter) that can still be a frame: a MAX_BODY body
// encodes to MAX_BODY + 1 bytes (one COBS block). Capping here means buf_ can never overflow.
const uint8_t MAX_CHUNK = static_cast<uint8_t>(proto::MAX_BODY + 1u);
// len_ value while an over-long chunk is dropped up to the next delimiter.
const uint8_t SKIPPING = 0xFF;
static_assert(MAX_CHUNK < SKIPPING, "SKIPPING must not be a real chunk length");
static_assert(MAX_CHUNK < 255, "a 0xFF COBS block (code + 254 bytes) must not fit in a chunk");

}  // namespace

ROVERLINK_NOINLINE void add_count(uint32_t& counter, uint8_t n) { counter += n; }

// All of the decoder is plain bytes and counters: one loop zeroes it.
FrameDecoder::FrameDecoder() { memset(static_cast<void*>(this), 0, sizeof *this); }

void FrameDecoder::reset() {
    len_ = 0;
    left_ = 0;
}

void FrameDecoder::reset_stats() {
    memset(&stats_, 0, sizeof stats_);  // one loop, not a store per byte of every counter
}

// Per-byte hot path: COBS is undone as the bytes arrive. Every encoded byte after a chunk's first
// decodes to exactly one byte, one place earlier: a data byte to itself, a code byte to the zero
// its block implies (a 0xFF block, the one kind without, cannot fit in MAX_CHUNK). The frame
// checks wait for the delimiter.
FrameDecoder::Result FrameDecoder::push(uint8_t byte) {
    if (byte == 0) {
        return finish_chunk();
    }
    const uint8_t n = len_;
    if (n >= MAX_CHUNK) {  // also while SKIPPING
        return drop_byte();
    }
    len_ = static_cast<uint8_t>(n + 1u);
    const uint8_t left = left_;
    if (left == 0) {  // a code byte: byte - 1 data bytes follow
        left_ = static_cast<uint8_t>(byte - 1u);
        if (n == 0) {
            return NONE;
        }
        byte = 0;
    } else {
        left_ = static_cast<uint8_t>(left - 1u);
    }
    buf_[n - 1u] = byte;
    return NONE;
}

FrameDecoder::Result FrameDecoder::drop_byte() {
    if (len_ == SKIPPING) {
        add_count(stats_.bytes_discarded);
        return NONE;
    }
    add_count(stats_.bytes_discarded, static_cast<uint8_t>(len_ + 1u));  // the chunk and this byte
    add_count(stats_.cobs_errors);
    len_ = SKIPPING;
    return ERR_OVERLONG;
}

void FrameDecoder::reject_payload() {
    if (frame_chunk_len_ == 0) {
        return;  // no FRAME to take back (called twice, or before any frame)
    }
    --stats_.frames_ok;
    add_count(stats_.value_errors);
    add_count(stats_.bytes_discarded, frame_chunk_len_);
    frame_chunk_len_ = 0;
}

FrameDecoder::Result FrameDecoder::finish_chunk() {
    const uint8_t chunk = len_;
    const uint8_t left = left_;
    reset();  // the next byte opens a new chunk, whatever this one turns out to be
    if (chunk == 0 || chunk == SKIPPING) {  // empty, or an over-long one already counted
        return NONE;
    }
    uint8_t* const b = buf_;
    uint32_t* counter = &stats_.cobs_errors;
    Result r = ERR_COBS;
    if (left != 0) {  // the chunk ends inside a block
        goto rejected;
    }
    {
        const uint8_t n = static_cast<uint8_t>(chunk - 1u);  // the code byte that opened it decodes to nothing
        proto::MessageBounds& bounds = bounds_;
        counter = &stats_.length_errors;
        r = ERR_LENGTH;
        if (n < 4) {
            goto rejected;
        }
        counter = &stats_.unknown_ids;
        r = ERR_UNKNOWN_ID;
        if (!proto::message_bounds(b[0], bounds)) {
            goto rejected;
        }
        const uint8_t payload_len = static_cast<uint8_t>(n - 4u);
        // The CRC's low byte, once read, makes room for CRC_EXTRA (hashed after the body, never
        // sent): one pass over the buffer.
        uint8_t* const tail = b + n - 2u;
        const uint16_t sent = static_cast<uint16_t>(tail[0] | (tail[1] << 8));
        tail[0] = bounds.crc_extra;
        counter = &stats_.crc_errors;
        r = ERR_CRC;
        if (crc16(b, static_cast<uint8_t>(n - 1u)) != sent) {
            goto rejected;
        }
        counter = &stats_.length_errors;
        r = ERR_LENGTH;
        if (payload_len < bounds.min_payload || payload_len > bounds.max_payload) {
            goto rejected;
        }
        payload_len_ = payload_len;
        frame_chunk_len_ = chunk;
        add_count(stats_.frames_ok);
        return FRAME;
    }
rejected:
    add_count(*counter);
    add_count(stats_.bytes_discarded, chunk);
    return r;
}

}  // namespace roverlink
