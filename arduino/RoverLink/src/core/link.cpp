#include "link.h"

#include <string.h>

namespace roverlink {

// tx_ is written before every read (a frame, or scratch memory): it needs no zeroing.
Link::Link(Stream& port) : port_(port) { memset(&c_, 0, sizeof c_); }

// Out of line: every message goes through this one call site (a few bytes per sender on AVR).
ROVERLINK_NOINLINE void Link::send_payload(uint8_t msg_id, uint8_t crc_extra, uint8_t len) {
    const size_t n = encode_frame(msg_id, c_.tx_seq, crc_extra, payload_slot(), len, tx_.frame, sizeof tx_.frame);
    if (n == 0) {
        return;  // cannot happen with a MAX_FRAME buffer; never send half a frame
    }
    port_.write(tx_.frame, n);
    add_count(c_.counts.frames_sent);
    ++c_.tx_seq;
}

void Link::account_seq(uint8_t seq) {
    if (c_.have_last_seq && seq != c_.last_seq) {
        add_count(c_.counts.seq_gaps, static_cast<uint8_t>(seq - static_cast<uint8_t>(c_.last_seq + 1u)));
    }
    c_.last_seq = seq;
    c_.have_last_seq = true;
}

}  // namespace roverlink
