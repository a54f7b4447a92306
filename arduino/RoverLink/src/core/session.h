// The session of the firmware: link (frames in and out) and every session rule of
// docs/control.md sections 1-3 and 6-7, over an App that owns the rest of the robot (control law,
// configuration, outputs). It is the part the design's "protocol + session" budget measures
// (docs/budgets.md), and links without the control law, PID or EEPROM code.
//
//   handshake and IDENTITY, the state machine (every state change through proto::step() on the
//   generated table), the watchdog, reliable requests with duplicate detection, ACK/NACK,
//   PING/PONG, LINK_STATS, LOG, the stream/lockstep FEEDBACK schedule, the boot_id.
//
// App is a template parameter (no vtable: on AVR, vtables live in SRAM). It must provide:
//
//   void session_actions(uint16_t actions);
//       The proto::Action bits of a row that fired; the App does MOTORS_SAFE, CLEAR_REASON (its
//       own fault bits) and MOTORS_ENABLE, before the session does the others.
//   const proto::SetConfig& config() const;
//       The configuration in force (IDLE's watchdog and stream rate, max_wheel_speed_mm_s, GET_CONFIG).
//   uint8_t set_config(const proto::SetConfig& c, uint8_t& detail);
//       SET_CONFIG, its ranges already checked: 0 when applied, else a NackReason (and detail).
//   void set_pid(const proto::SetPid& m);          SET_PID, wheel and ranges checked
//   void pid(uint8_t wheel, proto::SetPid& out);   GET_PID: the gains of wheel (< WHEEL_COUNT),
//       into `out`, which is in the TX frame buffer: send nothing meanwhile
//   uint8_t save_config();                         SAVE_CONFIG outside ARMED: 0 or a NackReason
//   void reset_odometry();                         RESET_ODOMETRY
//   void request(const proto::HostToMcu& m, uint8_t id);
//       Any other host request (SET_LIGHTS, GET_LIGHTS; its ranges unchecked), after the rules of
//       its kind (duplicates, NO_SESSION): answered with answer(), or with a reply built in out()
//       and sent by send_reply(); an id the App does not know is left unanswered.
//   void setpoint(int16_t left, int16_t right, int16_t steer_mrad, uint8_t seq);
//       A setpoint accepted in ARMED (ranges checked); the next control tick applies it.
//   uint8_t status_bits() const;                   its FEEDBACK status bits (SATURATED, ...)
//
// The App drives time: Firmware::poll() calls poll() (bytes), and per control tick
// check_watchdog(), maybe fault(), feedback_due() and send_feedback().
#ifndef ROVERLINK_CORE_SESSION_H
#define ROVERLINK_CORE_SESSION_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "../codec/codec.h"
#include "../generated/roverlink_protocol.h"
#include "../hal/board.h"
#include "../hal/stream.h"
#include "link.h"
#include "robot.h"
#include "version.h"

namespace roverlink {

static const FirmwareVersion FIRMWARE_VERSION = {ROVERLINK_FIRMWARE_VERSION_MAJOR, ROVERLINK_FIRMWARE_VERSION_MINOR,
                                                 ROVERLINK_FIRMWARE_VERSION_PATCH};

// The session's own state and the rules that do not call the App, compiled once (session.cpp);
// Session<App> adds the ones that do.
class SessionCore {
public:
    SessionCore(Stream& port, Board& board, const Robot& robot);

    proto::SessionState state() const { return v_.state; }
    uint32_t boot_id() const { return v_.boot_id; }
    proto::FailsafeReason failsafe_reason() const { return v_.reason; }
    uint16_t watchdog_ms() const { return v_.watchdog_ms; }  // granted by the last accepted HELLO
    uint32_t duplicates() const { return link_.counts().duplicates; }
    bool in_session() const { return v_.state > proto::SessionState::IDLE; }
    bool armed() const { return v_.state == proto::SessionState::ARMED; }
    const Link& link() const { return link_; }

    // For App::request(): the answer to the request being handled (remembered for its
    // duplicates), or a reply: req_seq, then the `len` bytes already in out() after it.
    void answer(uint8_t reason, uint8_t detail);  // 0: ACK, else NACK(reason, detail)
    void send_reply(uint8_t msg_id, uint8_t crc_extra, uint8_t len);
    proto::McuToHost& out() { return link_.out(); }

    // micros(), counting its wraps for IDENTITY.uptime_ms. The session reads the time only through
    // it: one call of the virtual micros() instead of one per reader.
    uint32_t clock();

    // The TX frame buffer, as scratch memory between frames (EEPROM images): Link::SCRATCH_SIZE.
    uint8_t* scratch() { return link_.scratch(); }

    // LOG(level, a text from flash followed by `tail_len` characters from RAM): the only text the
    // firmware sends. The texts are the App's (a number in one is the App's to write).
    void log(proto::LogLevel level, const char* flash_text, const char* tail = 0, uint8_t tail_len = 0);

protected:
    // How a request is handled before its own code runs (request()).
    enum Kind : uint8_t {  // two bits (kind_of())
        PLAIN = 0,     // HELLO, PING, setpoints: seq accounting and VALID_FRAME only
        TABLE = 1,     // ARM, DISARM: + duplicate detection; the state table answers
        RELIABLE = 2,  // SET_*, SAVE_CONFIG, RESET_ODOMETRY: + duplicate replay, NO_SESSION in IDLE
        QUERY = 3,     // GET_*: + duplicates answered afresh, NO_SESSION in IDLE
    };

    // fire()'s `guard`: the one guard that holds (no event has two), or 0 for none.
    static const uint8_t G_COMPATIBLE = static_cast<uint8_t>(proto::Guard::COMPATIBLE);
    static const uint8_t G_BOOT_ID = static_cast<uint8_t>(proto::Guard::BOOT_ID_MATCHES);

    // Small, often used members first (AVR's 6-bit load/store displacement).
    struct Vars {
        proto::SessionState state;
        proto::FailsafeReason reason;
        proto::FeedbackMode mode;  // granted by the last accepted HELLO
        uint8_t feedback_hz;       // granted by the last accepted HELLO
        uint8_t fb_countdown;      // ticks until the next stream FEEDBACK
        uint8_t req_id;            // the request being handled
        uint8_t req_seq;
        uint8_t dup_id;            // the last reliable request, for duplicate detection ...
        uint8_t dup_seq;
        uint8_t dup_reason;        // ... and its answer: 0 = ACK, else the NackReason
        uint8_t dup_detail;
        bool dup_valid;
        uint16_t watchdog_ms;      // granted by the last accepted HELLO
        uint32_t wrapped_ms;       // whole ms of the micros() wraps so far, for uptime_ms
        uint32_t last_micros;
        uint32_t last_valid_us;    // the watchdog's reference
        uint32_t boot_id;
    };

    // begin(): state cleared, boot_id drawn, IDLE's watchdog and stream rate from the config.
    void reset(uint32_t boot_counter, const proto::SetConfig& config);
    // The state change of `ev`; returns the row's actions (0: no row matched). `from` gets the
    // state before it.
    uint16_t step(proto::SessionEvent ev, uint8_t guard, proto::SessionState& from);
    // The row's session actions, after the App's (LATCH/CLEAR_REASON, FEED_WATCHDOG, ANNOUNCE,
    // REJECT_HELLO, ACK, NACK); `config` is the App's, for IDENTITY's values outside a session.
    void perform(uint16_t actions, proto::SessionEvent ev, proto::SessionState from, proto::FailsafeReason reason,
                 const proto::SetConfig& config);
    // After seq accounting and VALID_FRAME: the request's kind of handling (reliable requests'
    // duplicate rule, NO_SESSION in IDLE); false: already answered, stop.
    bool request(uint8_t msg_id, uint8_t seq);
    static Kind kind_of(uint8_t msg_id);
    void send_answer(uint8_t reason, uint8_t detail);  // 0: ACK, else NACK(reason, detail)
    void send_identity(proto::IdentityReason reason, const proto::SetConfig& config);
    void accept_hello(const proto::Hello& h, const proto::SetConfig& config);
    void send_pong(const proto::Ping& m);
    void send_link_stats();
    uint8_t session_status() const;
    bool feedback_due(bool applied, uint8_t config_hz);
    void send_feedback(proto::Feedback& f, uint8_t app_status);
    bool has(uint16_t capability) const { return (robot_.capabilities & capability) != 0; }
    // Index of the first speed over `max`, else `other` (check_ranges' answer).
    static uint8_t checked_speed(int16_t a, int16_t b, uint16_t max, uint8_t other);

    Vars v_;
    Board& board_;
    const Robot& robot_;
    Link link_;  // last: its buffers would push the other members out of AVR's short addressing
};

template <class App>
class Session : public SessionCore {
public:
    // Stores references only: safe to construct as a global before the Arduino core is up.
    Session(Stream& port, Board& board, const Robot& robot, App& app) : SessionCore(port, board, robot), app_(app) {}

    // Clears the session, draws the boot_id (mixing `boot_counter`, the board's entropy and the
    // clock), and fires INIT_DONE: the App's motors_safe, then the boot IDENTITY.
    void begin(uint32_t boot_counter) {
        reset(boot_counter, app_.config());
        fire(proto::SessionEvent::INIT_DONE, 0, proto::FailsafeReason::NONE);
    }

    // Handles the bytes received so far up to the end of the first complete frame, and dispatches
    // that frame (its reply goes out in the same pass). One frame per call: a host that keeps
    // sending cannot starve the control tick.
    void poll();

    // -- for the App's control tick ----------------------------------------------------------
    // In ARMED, WATCHDOG_EXPIRED when no valid frame came for the granted period.
    void check_watchdog(uint32_t now) {
        if (armed() && now - v_.last_valid_us >= static_cast<uint32_t>(v_.watchdog_ms) * 1000u) {
            fire(proto::SessionEvent::WATCHDOG_EXPIRED, 0, proto::FailsafeReason::COMM_TIMEOUT);
        }
    }
    void fault(proto::FailsafeReason reason) { fire(proto::SessionEvent::FAULT, 0, reason); }
    // Whether this tick sends FEEDBACK: stream (always in IDLE) on a countdown, lockstep when a
    // setpoint was applied.
    bool feedback_due(bool applied) { return SessionCore::feedback_due(applied, app_.config().feedback_hz); }
    // Fills FEEDBACK's boot_id, status and failsafe_reason, and sends it.
    void send_feedback(proto::Feedback& f) { SessionCore::send_feedback(f, app_.status_bits()); }

    // -- read-only view ------------------------------------------------------------------------
    uint8_t status() const { return static_cast<uint8_t>(session_status() | app_.status_bits()); }
    proto::FeedbackMode feedback_mode() const { return in_session() ? v_.mode : proto::FeedbackMode::STREAM; }
    uint8_t feedback_hz() const { return in_session() ? v_.feedback_hz : app_.config().feedback_hz; }

private:
    // Fires `ev`: the state change, the App's actions, then the session's. Returns the row's
    // action bits (0: no row), so the caller does ACCEPT_HELLO and APPLY_SETPOINT.
    uint16_t fire(proto::SessionEvent ev, uint8_t guard, proto::FailsafeReason reason) {
        proto::SessionState from;
        const uint16_t a = step(ev, guard, from);
        if (a != 0) {
            app_.session_actions(a);
            perform(a, ev, from, reason, app_.config());
        }
        return a;
    }

    void on_frame();

    App& app_;
};

// ------------------------------------------------------------------------------------------------
// Session<App>: the rules that call the App.

// Out of line: one call site, and a function of its own is what the firmware benchmark profiles
// (the decode and dispatch cycles are those spent inside it).
template <class App>
ROVERLINK_OUT_OF_LINE void Session<App>::poll() {
    FrameDecoder& decoder = link_.decoder();
    Stream& port = link_.port();
    // read() until it has nothing (-1), so no available() call per byte, and at most one frame per
    // call: a host that keeps sending cannot hold the loop.
    for (;;) {
        const int c = port.read();
        if (c < 0) {
            return;
        }
        if (decoder.push(static_cast<uint8_t>(c)) == FrameDecoder::FRAME) {
            on_frame();
            return;
        }
    }
}

// A frame the decoder accepted (COBS, length, id and CRC checked): docs/control.md section 1.
// One function for every message on purpose: the handlers share their answer tails in one body,
// which is what keeps link + session inside its flash budget (sharing the setpoint tail saved
// 24 B, ending the reliable requests in one answer call 8 B; docs/budgets.md).
template <class App>
void Session<App>::on_frame() {
    FrameDecoder& d = link_.decoder();
    const uint8_t id = d.msg_id();
    const uint8_t seq = d.seq();
    proto::HostToMcu m;
    const proto::DispatchResult r = proto::unpack_host_to_mcu(d.bounds(), id, d.payload(), d.payload_len(), m);
    if (r == proto::DISPATCH_BAD_PAYLOAD) {
        d.reject_payload();  // a value the spec does not allow: not a valid frame, no watchdog
        return;
    }
    // 1. seq accounting, 2. VALID_FRAME (an MCU-to-host message too, then ignored: 1.3).
    link_.account_seq(seq);
    fire(proto::SessionEvent::VALID_FRAME, 0, proto::FailsafeReason::NONE);
    if (r != proto::DISPATCH_OK || !request(id, seq)) {
        return;
    }
    // 3. The message's own handling. Ifs, not a switch: the ids span 0x01..0x21, and avr-gcc would
    // spend a 66-byte jump table on them.
    if (id == proto::Hello::ID) {
        const proto::Hello& h = m.hello;
        const bool compatible = h.protocol_version == proto::PROTOCOL_VERSION && h.spec_hash == proto::SPEC_HASH;
        if (fire(proto::SessionEvent::HELLO, compatible ? G_COMPATIBLE : 0, proto::FailsafeReason::NONE) &
            proto::Action::ACCEPT_HELLO) {
            accept_hello(h, app_.config());
        }
        return;
    }
    if (id == proto::Ping::ID) {
        send_pong(m.ping);
        return;
    }
    if (id == proto::Arm::ID) {
        fire(proto::SessionEvent::ARM, m.arm.boot_id == v_.boot_id ? G_BOOT_ID : 0, proto::FailsafeReason::NONE);
        return;
    }
    if (id == proto::Disarm::ID) {
        fire(proto::SessionEvent::DISARM, 0, proto::FailsafeReason::NONE);
        return;
    }
    if (id == proto::GetConfig::ID) {
        // CONFIG = req_seq followed by exactly the SET_CONFIG fields: copied into the frame buffer.
        static_assert(proto::Config::PAYLOAD_SIZE == 1 + proto::SetConfig::PAYLOAD_SIZE,
                      "CONFIG must be req_seq + SET_CONFIG");
        link_.reply().config = app_.config();
        send_reply(proto::Config::ID, proto::Config::CRC_EXTRA, proto::SetConfig::PAYLOAD_SIZE);
        return;
    }
    if (id == proto::GetLinkStats::ID) {
        send_link_stats();
        return;
    }
    // The reliable requests (and GET_PID's unknown wheel) end in one ACK or NACK.
    uint8_t why = 0;     // 0 (ACK) or the NackReason
    uint8_t detail = 0;  // the NACK's detail (an ACK has none)
    if (id == proto::SetPid::ID) {
        const proto::SetPid& p = m.set_pid;
        // docs/control.md 2: the wheel first (detail 0), then the gains
        if (p.wheel < proto::WHEEL_COUNT || p.wheel == proto::PID_ALL_WHEELS) {
            detail = proto::check_ranges(p);
        }
        if (detail == proto::ALL_FIELDS_VALID) {
            app_.set_pid(p);
        } else {
            why = static_cast<uint8_t>(proto::NackReason::OUT_OF_RANGE);
        }
    } else if (id == proto::GetPid::ID) {
        const uint8_t wheel = m.get_pid.wheel;
        if (wheel < proto::WHEEL_COUNT) {
            // PID = req_seq followed by exactly the SET_PID fields: filled in the frame buffer.
            static_assert(proto::Pid::PAYLOAD_SIZE == 1 + proto::SetPid::PAYLOAD_SIZE, "PID must be req_seq + SET_PID");
            proto::SetPid& p = link_.reply().pid;
            app_.pid(wheel, p);
            p.wheel = wheel;
            send_reply(proto::Pid::ID, proto::Pid::CRC_EXTRA, proto::SetPid::PAYLOAD_SIZE);
            return;
        }
        why = static_cast<uint8_t>(proto::NackReason::OUT_OF_RANGE);
    } else if (id == proto::SetConfig::ID) {
        detail = proto::check_ranges(m.set_config);
        why = static_cast<uint8_t>(proto::NackReason::OUT_OF_RANGE);
        if (detail == proto::ALL_FIELDS_VALID) {
            why = app_.set_config(m.set_config, detail);  // consistency, then applied
        }
    } else if (id == proto::SaveConfig::ID) {
        // EEPROM writes stall the loop: never while ARMED.
        why = armed() ? static_cast<uint8_t>(proto::NackReason::ARMED) : app_.save_config();
    } else if (id == proto::ResetOdometry::ID) {
        app_.reset_odometry();
    } else {
        // The setpoints, one tail for both. Checks in this order (docs/firmware.md): capability,
        // the state (the table's NACK), then (ARMED only) the first speed over
        // max_wheel_speed_mm_s or the first field check_ranges() refuses, whichever has the lower
        // field index.
        int16_t left;
        int16_t right = 0;
        int16_t steer_mrad = 0;
        uint8_t bad_field;
        uint16_t capability;
        if (id == proto::SetWheelSpeeds::ID) {
            const proto::SetWheelSpeeds& s = m.set_wheel_speeds;
            left = s.left_mm_s;
            right = s.right_mm_s;
            bad_field = proto::check_ranges(s);
            capability = proto::Capability::DIFF_DRIVE;
        } else if (id == proto::SetAckermann::ID) {
            const proto::SetAckermann& s = m.set_ackermann;
            left = s.speed_mm_s;
            steer_mrad = s.steering_mrad;
            bad_field = proto::check_ranges(s);
            capability = proto::Capability::ACKERMANN;
        } else {
            // The robot's own requests (SET_LIGHTS, GET_LIGHTS), their kind's rules done: the App
            // checks and answers them (answer() or send_reply()); the session only routes them.
            app_.request(m, id);
            return;
        }
        if (!has(capability)) {
            send_answer(static_cast<uint8_t>(proto::NackReason::UNSUPPORTED), 0);
        } else if (fire(proto::SessionEvent::SETPOINT, 0, proto::FailsafeReason::NONE) &
                   proto::Action::APPLY_SETPOINT) {
            const uint8_t bad = checked_speed(left, right, app_.config().max_wheel_speed_mm_s, bad_field);
            if (bad != proto::ALL_FIELDS_VALID) {
                send_answer(static_cast<uint8_t>(proto::NackReason::OUT_OF_RANGE), bad);
            } else {
                app_.setpoint(left, right, steer_mrad, v_.req_seq);  // the next ticks apply it
            }
        }
        return;
    }
    answer(why, detail);
}

}  // namespace roverlink

#endif  // ROVERLINK_CORE_SESSION_H
