// Byte-at-a-time frame decoder: feed it every byte read from the serial port. It undoes COBS as
// the bytes arrive (at most one frame's worth) and checks the frame at its delimiter: the COBS
// blocks, the length, the msg_id and the CRC.
#ifndef ROVERLINK_CODEC_FRAME_DECODER_H
#define ROVERLINK_CODEC_FRAME_DECODER_H

#include <stddef.h>
#include <stdint.h>

#include "../generated/roverlink_protocol.h"

namespace roverlink {

// The decoder's counters: the spec's decoder_counters field set (LINK_STATS carries them in this
// order). cobs_errors includes chunks dropped for being over-long, value_errors the frames whose
// payload the generated unpack() refused (see reject_payload), bytes_discarded the encoded bytes
// of rejected chunks (delimiters not counted).
typedef proto::DecoderCounters DecoderStats;

// counter += n. Out of line on purpose: a 32-bit add inlined at every counter costs ~40 bytes of
// AVR flash each (the decoder's, the link's and the session's counters all use it).
void add_count(uint32_t& counter, uint8_t n = 1);

class FrameDecoder {
public:
    enum Result : uint8_t {
        NONE = 0,        // need more bytes (also: empty chunk, or still skipping an over-long one)
        FRAME,           // a good frame: msg_id(), seq(), payload(), payload_len() are valid
        ERR_COBS,        // chunk is not valid COBS
        ERR_OVERLONG,    // no delimiter within MAX_FRAME bytes: dropped up to the next 0x00
        ERR_LENGTH,      // body shorter than 4 bytes, or payload length wrong for its msg_id
        ERR_UNKNOWN_ID,  // msg_id not in the protocol
        ERR_CRC          // checksum mismatch (with that msg_id's CRC_EXTRA)
    };

    FrameDecoder();

    Result push(uint8_t byte);

    // Drops a partially received chunk (e.g. after the port was reopened); keeps the stats.
    void reset();

    // Valid after push() returned FRAME, until the next push().
    uint8_t msg_id() const { return buf_[0]; }
    uint8_t seq() const { return buf_[1]; }
    const uint8_t* payload() const { return buf_ + 2; }
    uint8_t payload_len() const { return payload_len_; }
    // msg_id's row of the message table, looked up once (for proto::unpack_host_to_mcu(b, ...)).
    const proto::MessageBounds& bounds() const { return bounds_; }

    // Call right after push() returned FRAME when unpack()/dispatch refused the payload (a value
    // the spec does not allow): the frame is recounted as a value error and its bytes as
    // discarded, so these counters match the Python decoder's.
    void reject_payload();

    const DecoderStats& stats() const { return stats_; }
    void reset_stats();

private:
    Result finish_chunk();
    Result drop_byte();

    uint8_t len_;              // encoded bytes of the current chunk so far, or SKIPPING
    uint8_t left_;             // data bytes still to come in the current COBS block
    uint8_t payload_len_;
    uint8_t frame_chunk_len_;  // encoded length of the last FRAME, for reject_payload()
    proto::MessageBounds bounds_;
    // The decoded body of the current chunk (encoded byte k lands in buf_[k - 1]).
    uint8_t buf_[proto::MAX_BODY];
    DecoderStats stats_;
};

}  // namespace roverlink

#endif  // ROVERLINK_CODEC_FRAME_DECODER_H
