// Test harness for the firmware core: CHECK counting, and a Host that talks to a Sim through the
// real codec (encode_message on the way in, FrameDecoder + generated unpack on the way out).
#ifndef ROVERLINK_TESTS_CORE_HARNESS_H
#define ROVERLINK_TESTS_CORE_HARNESS_H

#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <vector>

#include <RoverLink.h>

#include "sim.h"

namespace harness {

extern unsigned g_passed;
extern unsigned g_failed;
extern char g_ctx[200];  // what is being tested; printed with each failure

#define CHECK(cond)                                                                              \
    do {                                                                                         \
        if (cond) {                                                                              \
            ++harness::g_passed;                                                                 \
        } else {                                                                                 \
            ++harness::g_failed;                                                                 \
            if (harness::g_failed <= 80) {                                                       \
                printf("%s:%d: CHECK(%s) failed [%s]\n", __FILE__, __LINE__, #cond, harness::g_ctx); \
            }                                                                                    \
        }                                                                                        \
    } while (0)

#define CHECK_EQ(a, b)                                                                                 \
    do {                                                                                               \
        const long long va_ = static_cast<long long>(a);                                               \
        const long long vb_ = static_cast<long long>(b);                                               \
        if (va_ == vb_) {                                                                              \
            ++harness::g_passed;                                                                       \
        } else {                                                                                       \
            ++harness::g_failed;                                                                       \
            if (harness::g_failed <= 80) {                                                             \
                printf("%s:%d: CHECK_EQ(%s, %s) failed: %lld != %lld [%s]\n", __FILE__, __LINE__, #a, #b, \
                       va_, vb_, harness::g_ctx);                                                      \
            }                                                                                          \
        }                                                                                              \
    } while (0)

#define CONTEXT(...) snprintf(harness::g_ctx, sizeof(harness::g_ctx), __VA_ARGS__)

typedef std::vector<uint8_t> Bytes;

struct RxFrame {
    uint8_t id;
    uint8_t seq;
    Bytes payload;
};

// The host end of the link.
class Host {
public:
    explicit Host(Sim& sim) : sim_(sim), next_seq_(1), mcu_seq_gaps_(0), have_mcu_seq_(false), last_mcu_seq_(0) {}

    // Encodes with the next host seq and feeds it (not yet handled: call run()).
    template <class M>
    uint8_t send(const M& m) {
        const uint8_t seq = next_seq_++;
        send_seq(m, seq);
        return seq;
    }
    template <class M>
    void send_seq(const M& m, uint8_t seq) {
        uint8_t buf[roverlink::proto::MAX_FRAME];
        const size_t n = roverlink::encode_message(m, seq, buf, sizeof buf);
        sim_.feed(buf, n);
    }
    void raw(const Bytes& b) { sim_.feed(b.data(), b.size()); }
    void set_next_seq(uint8_t s) { next_seq_ = s; }
    uint8_t next_seq() const { return next_seq_; }

    // Handles what was fed (and advances time by `us`), then collects what the firmware sent.
    void run(uint64_t us = 0) {
        sim_.advance_us(us);
        pump();
    }

    void pump() {
        uint8_t buf[512];
        size_t n;
        while ((n = sim_.read(buf, sizeof buf)) > 0) {
            for (size_t i = 0; i < n; ++i) {
                if (decoder_.push(buf[i]) == roverlink::FrameDecoder::FRAME) {
                    RxFrame f;
                    f.id = decoder_.msg_id();
                    f.seq = decoder_.seq();
                    f.payload.assign(decoder_.payload(), decoder_.payload() + decoder_.payload_len());
                    if (have_mcu_seq_ && f.seq != static_cast<uint8_t>(last_mcu_seq_ + 1)) {
                        ++mcu_seq_gaps_;
                    }
                    have_mcu_seq_ = true;
                    last_mcu_seq_ = f.seq;
                    frames.push_back(f);
                }
            }
        }
    }

    void clear() { frames.clear(); }
    void resync_mcu_seq() { have_mcu_seq_ = false; }  // after a power cycle the MCU starts again at 0

    template <class M>
    size_t count() const {
        size_t n = 0;
        for (size_t i = 0; i < frames.size(); ++i) {
            n += frames[i].id == M::ID;
        }
        return n;
    }

    template <class M>
    std::vector<M> all() const {
        std::vector<M> out;
        for (size_t i = 0; i < frames.size(); ++i) {
            M m;
            if (frames[i].id == M::ID && roverlink::proto::unpack(frames[i].payload.data(),
                                                                  static_cast<uint8_t>(frames[i].payload.size()), m)) {
                out.push_back(m);
            }
        }
        return out;
    }

    template <class M>
    bool last(M& out) const {
        for (size_t i = frames.size(); i-- > 0;) {
            if (frames[i].id == M::ID) {
                return roverlink::proto::unpack(frames[i].payload.data(), static_cast<uint8_t>(frames[i].payload.size()),
                                                out);
            }
        }
        return false;
    }

    std::vector<RxFrame> frames;
    unsigned mcu_seq_gaps() const { return mcu_seq_gaps_; }
    const roverlink::DecoderStats& rx_stats() const { return decoder_.stats(); }

private:
    Sim& sim_;
    roverlink::FrameDecoder decoder_;
    uint8_t next_seq_;
    unsigned mcu_seq_gaps_;
    bool have_mcu_seq_;
    uint8_t last_mcu_seq_;
};

}  // namespace harness

#endif  // ROVERLINK_TESTS_CORE_HARNESS_H
