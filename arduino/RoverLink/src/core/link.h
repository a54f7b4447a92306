// The link layer of the firmware: the frame decoder, the single TX frame buffer, the per-direction
// seq counter, and the link counters the session reports in LINK_STATS.
#ifndef ROVERLINK_CORE_LINK_H
#define ROVERLINK_CORE_LINK_H

#include <stddef.h>
#include <stdint.h>

#include "../codec/codec.h"
#include "../hal/stream.h"

namespace roverlink {

class Link {
public:
    explicit Link(Stream& port);

    FrameDecoder& decoder() { return decoder_; }
    const FrameDecoder& decoder() const { return decoder_; }
    Stream& port() { return port_; }

    // Packs, frames and writes one message with the next seq. Replies go out in the same loop
    // pass that handled the request (docs/control.md section 7).
    template <class M>
    void send(const M& m) {
        static_assert(M::PAYLOAD_MAX <= proto::MAX_PAYLOAD, "message payload exceeds MAX_PAYLOAD");
        send_payload(M::ID, M::CRC_EXTRA, proto::pack(m, payload_slot()));  // packed in place
    }

    // For messages built straight into the frame buffer (no message struct on the stack): write
    // up to proto::MAX_PAYLOAD bytes at payload_slot(), or the fields of a message in out(), then
    // send_payload().
    uint8_t* payload_slot() { return tx_.frame + 3; }
    proto::McuToHost& out() { return tx_.slot.msg; }
    // A GET_* answer (PID, CONFIG): req_seq, then exactly the fields of the SET_* message.
    struct Reply {
        uint8_t req_seq;
        union {
            proto::SetPid pid;
            proto::SetConfig config;
        };
    };
    Reply& reply() { return tx_.slot.reply; }
    void send_payload(uint8_t msg_id, uint8_t crc_extra, uint8_t len);

    // The TX buffer doubles as scratch memory between frames (EEPROM images).
    uint8_t* scratch() { return tx_.frame; }
    static const uint8_t SCRATCH_SIZE = proto::MAX_FRAME;

    // Receive-side seq accounting (docs/control.md 1.2.1).
    void account_seq(uint8_t seq);
    void restart_seq() { c_.have_last_seq = false; }

    // A reliable request received again (answered, not re-applied).
    void count_duplicate() { add_count(c_.counts.duplicates); }

    // The link's own LINK_STATS counters: the spec's link_counters field set, which LINK_STATS
    // carries after the decoder's. rx_overruns stays 0 (the Arduino core drops UART overruns
    // without a trace); it is kept so that LINK_STATS's tail is one copy.
    typedef proto::LinkCounters Counts;
    const Counts& counts() const { return c_.counts; }
    uint8_t next_tx_seq() const { return c_.tx_seq; }

private:
    struct Counters {  // zeroed as one block by the constructor
        Counts counts;
        uint8_t tx_seq;
        uint8_t last_seq;
        bool have_last_seq;
    };

    // The frame being sent; its payload, at offset 3, is also the message structs' wire image.
    union Tx {
        uint8_t frame[proto::MAX_FRAME];
        struct {
            uint8_t head[3];  // COBS code, msg_id, seq
            union {
                proto::McuToHost msg;
                Reply reply;
            };
        } slot;
    };
    static_assert(sizeof(Tx) == proto::MAX_FRAME, "every message must fit the frame buffer");

    Stream& port_;
    Counters c_;
    FrameDecoder decoder_;
    Tx tx_;
};

}  // namespace roverlink

#endif  // ROVERLINK_CORE_LINK_H
