#include "link.h"

#include <string.h>

namespace roverlink {

Link::Link(Stream& port)
    : port_(port), frames_sent_(0), seq_gaps_(0), tx_seq_(0), last_seq_(0), have_last_seq_(false) {
    memset(tx_, 0, sizeof tx_);
}

// Out of line: every message goes through this one call site (a few bytes per sender on AVR).
ROVERLINK_NOINLINE void Link::send_payload(uint8_t msg_id, uint8_t crc_extra, uint8_t len) {
    const size_t n = encode_frame(msg_id, tx_seq_, crc_extra, payload_slot(), len, tx_, sizeof tx_);
    if (n == 0) {
        return;  // cannot happen with a MAX_FRAME buffer; never send half a frame
    }
    port_.write(tx_, n);
    add_count(frames_sent_);
    ++tx_seq_;
}

void Link::account_seq(uint8_t seq) {
    if (have_last_seq_ && seq != last_seq_) {
        add_count(seq_gaps_, static_cast<uint8_t>(seq - static_cast<uint8_t>(last_seq_ + 1u)));
    }
    last_seq_ = seq;
    have_last_seq_ = true;
}

}  // namespace roverlink
