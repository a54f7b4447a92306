// Fuzz target: the whole firmware core (Session + Firmware + EEPROM image) on the native board
// layer, for each reference robot, fed host bytes with time advancing. The input is a script of
// operations (below); raw bytes reach every corner of the decoder, and well-formed frames built
// from input bytes (valid COBS and CRC, the live boot_id where ARM needs it) reach the session and
// the control law, which random bytes alone almost never would.
//
// After every poll() the invariants of docs/control.md are checked (FUZZ_CHECK aborts):
//   - out of ARMED the motors are safe: no target, no drive effort, ESC neutral, except for a
//     RAMP_DOWN still ramping, whose ramped speeds only shrink;
//   - ARMED is entered only by an ACKed ARM, and lasts at most the watchdog period and one tick
//     after the last valid frame; FAILSAFE is left only by an ACKed ARM or DISARM, an accepted or
//     rejected HELLO, or a reboot, and always carries its reason;
//   - the configuration in force and the PID gains are within their spec ranges and consistent;
//   - every counter (decoder, link, ticks, duplicates) only grows within a boot;
//   - everything the firmware sends is a valid frame of a known MCU-to-host message whose values
//     are within the spec, with the per-direction seq counting up by one.
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <RoverLink.h>

#include "fuzz_check.h"
#include "hal/native/memory_stream.h"
#include "hal/native/native_board.h"
#include "profiles.h"

using namespace roverlink;
using proto::SessionState;

namespace {

const uint32_t STEP_US = 1000;  // the loop polls once per simulated ms
const uint8_t HOST_IDS[] = {proto::Hello::ID,     proto::Ping::ID,          proto::Arm::ID,
                            proto::Disarm::ID,    proto::SetPid::ID,        proto::GetPid::ID,
                            proto::SetConfig::ID, proto::GetConfig::ID,     proto::SaveConfig::ID,
                            proto::ResetOdometry::ID, proto::GetLinkStats::ID, proto::SetWheelSpeeds::ID,
                            proto::SetAckermann::ID};

// The input, read front to back; past its end every read is 0.
struct Input {
    const uint8_t* p;
    size_t n;
    uint8_t byte() { return n != 0 ? (--n, *p++) : 0; }
    uint16_t u16() { return static_cast<uint16_t>(byte() | (byte() << 8)); }
};

// What one poll() made the firmware send, as the invariants need it.
struct Sent {
    bool arm_acked;
    bool disarm_acked;
    bool hello_answered;
};

// MCU-to-host messages: each must pass its spec's checks.
struct Vet {
    Sent* sent;
    template <class M>
    void handle(const M& m, uint8_t) {
        FUZZ_CHECK(proto::check_ranges(m) == proto::ALL_FIELDS_VALID);
    }
    void handle(const proto::Ack& m, uint8_t) {
        sent->arm_acked |= m.req_id == proto::Arm::ID;
        sent->disarm_acked |= m.req_id == proto::Disarm::ID;
    }
    void handle(const proto::Identity& m, uint8_t) {
        FUZZ_CHECK(proto::check_ranges(m) == proto::ALL_FIELDS_VALID);
        sent->hello_answered |= m.reason != proto::IdentityReason::BOOT;
    }
};

struct Counters {
    DecoderStats decoder;
    Link::Counts link;
    uint16_t tick;
    uint32_t ticks_skipped;
};

bool grew(const uint32_t* before, const uint32_t* after, size_t n) {
    for (size_t i = 0; i < n; ++i) {
        if (after[i] < before[i]) {
            return false;
        }
    }
    return true;
}

class Rig {
public:
    Rig(const Robot& robot, uint32_t seed) : robot_(robot), board_(seed), fw_(0), now_(0), host_seq_(0) { boot(); }
    ~Rig() { delete fw_; }

    NativeBoard& board() { return board_; }
    Firmware& fw() { return *fw_; }
    uint8_t next_seq() { return host_seq_++; }
    uint8_t last_seq() const { return static_cast<uint8_t>(host_seq_ - 1); }

    void boot() {
        delete fw_;
        board_.power_cycle();
        board_.set_micros(now_);
        port_.clear();
        fw_ = new Firmware(port_, board_, robot_);
        host_.reset();
        have_mcu_seq_ = false;
        state_ = SessionState::BOOT;
        for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
            last_ramp_[w] = 1e9f;
        }
        fw_->begin();
        snapshot(counters_);
        after_poll();
    }

    void feed(const uint8_t* data, size_t n) { port_.host_write(data, n); }

    template <class M>
    void send(const M& m, uint8_t seq) {
        uint8_t buf[proto::MAX_FRAME];
        feed(buf, encode_message(m, seq, buf, sizeof buf));
    }

    // Every byte fed so far handled, one poll() at a time (each handles at most one frame).
    void poll_all() {
        do {
            fw_->poll();
            after_poll();
        } while (port_.pending_to_mcu() != 0);
    }

    // Time passes in 1 ms steps with a poll() after each (ticks come from micros()).
    void advance_ms(uint32_t ms) {
        for (uint32_t i = 0; i < ms; ++i) {
            now_ += STEP_US;
            board_.set_micros(now_);
            poll_all();
        }
    }

    // The loop held up (a blocking write elsewhere): one poll() long after the last.
    void stall_us(uint32_t us) {
        now_ += us;
        board_.set_micros(now_);
        poll_all();
    }

private:
    void snapshot(Counters& c) const {
        c.decoder = fw_->link().decoder().stats();
        c.link = fw_->link().counts();
        c.tick = fw_->tick();
        c.ticks_skipped = fw_->ticks_skipped();
    }

    Sent drain() {
        Sent sent = {false, false, false};
        uint8_t buf[256];
        size_t n;
        while ((n = port_.host_read(buf, sizeof buf)) > 0) {
            for (size_t i = 0; i < n; ++i) {
                const FrameDecoder::Result r = host_.push(buf[i]);
                FUZZ_CHECK(r == FrameDecoder::NONE || r == FrameDecoder::FRAME);
                if (r != FrameDecoder::FRAME) {
                    continue;
                }
                FUZZ_CHECK(!have_mcu_seq_ || host_.seq() == static_cast<uint8_t>(mcu_seq_ + 1));
                have_mcu_seq_ = true;
                mcu_seq_ = host_.seq();
                Vet vet = {&sent};
                FUZZ_CHECK(proto::dispatch_mcu_to_host(host_.msg_id(), host_.seq(), host_.payload(), host_.payload_len(),
                                                       vet) == proto::DISPATCH_OK);
            }
        }
        return sent;
    }

    void after_poll() {
        const Sent sent = drain();
        const Firmware& fw = *fw_;
        const SessionState was = state_;
        const SessionState now = fw.state();
        state_ = now;
        // Arming only by an ACKed ARM; FAILSAFE latched until ARM, DISARM or a HELLO.
        if (now == SessionState::ARMED && was != SessionState::ARMED) {
            FUZZ_CHECK(sent.arm_acked);
        }
        if (was == SessionState::FAILSAFE && now != SessionState::FAILSAFE) {
            FUZZ_CHECK(sent.arm_acked || sent.disarm_acked || sent.hello_answered);
        }
        FUZZ_CHECK((now == SessionState::FAILSAFE) == (fw.failsafe_reason() != proto::FailsafeReason::NONE));
        FUZZ_CHECK(((fw.status() & proto::Status::FAILSAFE) != 0) == (now == SessionState::FAILSAFE));
        FUZZ_CHECK(((fw.status() & proto::Status::ARMED) != 0) == (now == SessionState::ARMED));
        check_config(fw);
        check_outputs(fw, now == SessionState::ARMED);
        // Counters only grow.
        Counters c;
        snapshot(c);
        // The watchdog: ARMED lasts no longer than the granted period after the last valid frame,
        // plus the one control tick that notices (a frame refused for its values is not valid).
        if (c.decoder.frames_ok != counters_.decoder.frames_ok) {
            last_valid_us_ = now_;
        }
        if (now == SessionState::ARMED) {
            FUZZ_CHECK(now_ - last_valid_us_ < fw.watchdog_ms() * 1000u + control::TICK_US + STEP_US);
        }
        FUZZ_CHECK(grew(&counters_.decoder.frames_ok, &c.decoder.frames_ok, sizeof c.decoder / 4));
        FUZZ_CHECK(grew(&counters_.link.seq_gaps, &c.link.seq_gaps, sizeof c.link / 4));
        // The 16-bit tick counter wraps after 655 s of ticks; an input can simulate longer than that.
        FUZZ_CHECK(static_cast<uint16_t>(c.tick - counters_.tick) < 0x8000u && c.ticks_skipped >= counters_.ticks_skipped);
        counters_ = c;
    }

    static void check_config(const Firmware& fw) {
        const proto::SetConfig& cfg = fw.config();
        FUZZ_CHECK(proto::check_ranges(cfg) == proto::ALL_FIELDS_VALID);
        FUZZ_CHECK(config::inconsistent_field(cfg) == proto::ALL_FIELDS_VALID);
        for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
            proto::SetPid p;
            p.wheel = w;
            control::gains_to(p, fw.gains(w));
            FUZZ_CHECK(proto::check_ranges(p) == proto::ALL_FIELDS_VALID);
        }
    }

    void check_outputs(const Firmware& fw, bool armed) {
        const proto::SetConfig& cfg = fw.config();
        bool ramping = false;
        for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
            FUZZ_CHECK(fw.effort(w) >= -1000 && fw.effort(w) <= 1000);
            const float r = fw.ramped(w) < 0 ? -fw.ramped(w) : fw.ramped(w);
            if (!armed) {
                FUZZ_CHECK(fw.target(w) == 0);
                FUZZ_CHECK(r <= last_ramp_[w]);  // out of ARMED, RAMP_DOWN only slows down
                ramping = ramping || r != 0.0f;
            }
            last_ramp_[w] = armed ? 1e9f : r;
        }
        // The outputs follow a config change at the next tick (the safe mode, the ESC's neutral).
        if (memcmp(&cfg, &last_cfg_, sizeof cfg) != 0) {
            last_cfg_ = cfg;
            cfg_tick_ = fw.tick();
        }
        if (armed || ramping || fw.tick() == cfg_tick_) {
            return;
        }
        // At rest out of ARMED: nothing driven, the ESC at neutral.
        const bool esc = (robot_.capabilities & proto::Capability::ESC) != 0;
        const uint8_t driven = (robot_.capabilities & proto::Capability::DIFF_DRIVE) ? proto::WHEEL_COUNT : 1;
        for (uint8_t w = esc ? 1 : 0; w < driven; ++w) {
            const NativeBoard::Motor& m = board_.motor(w);
            FUZZ_CHECK(m.effort == 0 && (m.calls == 0 || m.mode != MotorMode::DRIVE));
        }
        if (esc && board_.esc_calls() != 0) {
            FUZZ_CHECK(board_.esc_us() == control::esc_pulse_us(0, cfg));
        }
    }

    const Robot& robot_;
    NativeBoard board_;
    MemoryStream port_;
    Firmware* fw_;
    FrameDecoder host_;
    uint32_t now_;
    uint8_t host_seq_;
    bool have_mcu_seq_ = false;
    uint8_t mcu_seq_ = 0;
    SessionState state_ = SessionState::BOOT;
    Counters counters_;
    float last_ramp_[proto::WHEEL_COUNT];
    proto::SetConfig last_cfg_ = proto::SetConfig();
    uint16_t cfg_tick_ = 0;
    uint32_t last_valid_us_ = 0;
};

// A frame of a host-to-MCU message (or any id) with a payload taken from the input.
void op_frame(Rig& rig, Input& in, uint8_t arg) {
    const uint8_t pick = in.byte();
    const uint8_t id = (arg & 1) ? pick : HOST_IDS[pick % sizeof HOST_IDS];
    proto::MessageBounds b;
    if (!proto::message_bounds(id, b)) {
        return;
    }
    const uint8_t seq = (arg & 2) ? rig.last_seq() : rig.next_seq();  // a retry, or the next one
    const uint8_t span = static_cast<uint8_t>(b.max_payload - b.min_payload);
    const uint8_t len = static_cast<uint8_t>(b.min_payload + (span != 0 ? in.byte() % (span + 1) : 0));
    uint8_t payload[proto::MAX_PAYLOAD];
    for (uint8_t i = 0; i < len; ++i) {
        payload[i] = in.byte();
    }
    uint8_t frame[proto::MAX_FRAME];
    rig.feed(frame, encode_frame(id, seq, b.crc_extra, payload, len, frame, sizeof frame));
}

// The requests a host makes, with the values that let them through (boot_id, spec hash).
void op_session(Rig& rig, Input& in, uint8_t arg) {
    Firmware& fw = rig.fw();
    const uint8_t seq = rig.next_seq();
    switch (arg % 8) {
    case 0: {
        const uint8_t mode = in.byte();
        const proto::Hello h = {proto::PROTOCOL_VERSION, proto::SPEC_HASH, in.u16(),
                                static_cast<proto::FeedbackMode>(mode & 1), in.byte()};
        rig.send(h, seq);
        break;
    }
    case 1: {
        const proto::Arm a = {fw.boot_id()};
        rig.send(a, seq);
        break;
    }
    case 2: {
        const proto::Disarm d = {};
        rig.send(d, seq);
        break;
    }
    case 3: {
        const int16_t left = static_cast<int16_t>(in.u16());
        const int16_t right = static_cast<int16_t>(in.u16());
        const proto::SetWheelSpeeds s = {static_cast<int16_t>(left % 1200), static_cast<int16_t>(right % 1200)};
        const proto::SetAckermann a = {static_cast<int16_t>(left % 2500), static_cast<int16_t>(right % 1600)};
        if (in.byte() & 1) {
            rig.send(s, seq);
        } else {
            rig.send(a, seq);
        }
        break;
    }
    case 4: {
        const proto::SaveConfig s = {};
        rig.send(s, seq);
        break;
    }
    case 5: {  // the config in force with one byte changed
        uint8_t payload[proto::SetConfig::PAYLOAD_SIZE];
        proto::pack(fw.config(), payload);
        const uint8_t at = in.byte();
        payload[at % sizeof payload] = in.byte();
        uint8_t frame[proto::MAX_FRAME];
        rig.feed(frame, encode_frame(proto::SetConfig::ID, seq, proto::SetConfig::CRC_EXTRA, payload, sizeof payload,
                                     frame, sizeof frame));
        break;
    }
    case 6: {  // gains near the ones in force
        proto::SetPid p;
        p.wheel = in.byte() % 3 == 2 ? proto::PID_ALL_WHEELS : in.byte() % proto::WHEEL_COUNT;
        control::gains_to(p, fw.gains(0));
        p.kp = static_cast<float>(in.byte()) / 16.0f;
        p.ki = static_cast<float>(in.byte()) / 8.0f;
        rig.send(p, seq);
        break;
    }
    default: {
        const proto::ResetOdometry r = {};
        rig.send(r, seq);
        break;
    }
    }
}

}  // namespace

// Input: byte 0 picks the robot and its EEPROM at first boot; then operations, one byte each
// (kind in bits 0-2, argument in bits 3-7) and their operands.
extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    Input in = {data, size};
    const uint8_t head = in.byte();
    const sim_profiles::Profile* profile = sim_profiles::at(head % sim_profiles::count());
    Rig rig(*profile->robot, 1u + head);
    while (in.n != 0) {
        const uint8_t op = in.byte();
        const uint8_t arg = static_cast<uint8_t>(op >> 3);
        switch (op & 7) {
        case 0: {  // raw bytes
            const size_t n = arg + 1u < in.n ? arg + 1u : in.n;
            rig.feed(in.p, n);
            in.p += n;
            in.n -= n;
            break;
        }
        case 1:
            op_frame(rig, in, arg);
            break;
        case 2:
            op_session(rig, in, arg);
            break;
        case 3:  // time: up to 255 ms in 1 ms steps, or a stalled loop of up to 3.1 s
            if (arg == 31) {
                rig.stall_us(in.u16() * 48u);
            } else {
                rig.advance_ms(in.byte() % (arg + 1u) + 1u);
            }
            break;
        case 4:  // the wheels turn
            for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
                rig.board().add_encoder(w, static_cast<int8_t>(in.byte()) * (arg + 1));
            }
            break;
        case 5:  // reset: a power cycle, maybe with a bit flipped in the EEPROM image
            if (arg & 1) {
                rig.board().corrupt_eeprom(static_cast<uint16_t>(config::IMAGE_ADDR + in.byte() % config::IMAGE_SIZE),
                                           static_cast<uint8_t>(1u << (arg >> 1) % 8));
            }
            rig.boot();
            break;
        case 6:  // the EEPROM fails
            rig.board().set_eeprom_write_fails(arg & 1);
            rig.board().set_eeprom_write_xor(static_cast<uint8_t>(arg >> 1));
            break;
        default:
            rig.poll_all();
            break;
        }
        rig.poll_all();
    }
    rig.advance_ms(20);  // let the last bytes and two ticks through the checks
    return 0;
}
