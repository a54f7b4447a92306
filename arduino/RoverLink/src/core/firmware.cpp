#include "firmware.h"

#include <string.h>

namespace roverlink {

using proto::FailsafeReason;
using proto::NackReason;
using proto::SessionEvent;
using proto::SessionState;

namespace {

// LOG texts live in flash (PROGMEM on AVR), never in SRAM. Each is <= 60 ASCII characters; the
// exact texts are listed in docs/firmware.md for the emulator to reproduce.
const char LOG_NO_IMAGE[] ROVERLINK_PROGMEM = "config: no EEPROM image for this version, using defaults";
const char LOG_BAD_CRC[] ROVERLINK_PROGMEM = "config: EEPROM CRC error, using defaults";
const char LOG_INVALID[] ROVERLINK_PROGMEM = "config: EEPROM values invalid, using defaults";
const char LOG_LATE[] ROVERLINK_PROGMEM = "control: poll() late, ticks skipped: ";

const uint8_t STALL_TICKS = 50;                // docs/control.md 4.8: 0.5 s ...
const int16_t STALL_EFFORT = 300;              // ... at |u| >= 300 permille without a count
const uint8_t LATE_LOG_HOLDOFF_TICKS = 100;    // at most one "late" LOG per second
const uint32_t MS_PER_MICROS_WRAP = 4294967u;  // 2^32 us, in whole ms

const uint8_t G_COMPATIBLE = 1u << static_cast<uint8_t>(proto::Guard::COMPATIBLE);
const uint8_t G_BOOT_ID = 1u << static_cast<uint8_t>(proto::Guard::BOOT_ID_MATCHES);

struct Guards {
    uint8_t bits;
    bool check(proto::Guard g) const { return (bits >> static_cast<uint8_t>(g)) & 1u; }
};

// A 32-bit finaliser (xorshift-multiply): every input bit affects every output bit.
ROVERLINK_NOINLINE uint32_t mix32(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7FEB352DUL;
    x ^= x >> 15;
    x *= 0x846CA68BUL;
    x ^= x >> 16;
    return x;
}

int32_t invert_if(int32_t raw, bool invert) {
    // Two's complement negation without signed overflow (INT32_MIN stays INT32_MIN).
    return invert ? static_cast<int32_t>(0u - static_cast<uint32_t>(raw)) : raw;
}

int16_t abs16(int16_t x) { return x < 0 ? static_cast<int16_t>(-x) : x; }

uint8_t checked_speed(int16_t a, int16_t b, uint16_t max, uint8_t other) {
    // Index of the first speed over the limit, else `other` (check_ranges' answer).
    return static_cast<uint16_t>(abs16(a)) > max ? 0 : (static_cast<uint16_t>(abs16(b)) > max ? 1 : other);
}

}  // namespace

struct Firmware::Rx {
    Firmware& fw;
    template <class M>
    void handle(const M& m, uint8_t seq) {
        fw.on_message(m, seq);
    }
};

Firmware::Firmware(Stream& port, Board& board, const Robot& robot)
    : v_(), port_(port), board_(board), robot_(robot), link_(port) {}

// ------------------------------------------------------------------------------------------------
// Boot

void Firmware::begin() {
    if (v_.state != proto::INITIAL_STATE) {
        return;  // begin() runs once per boot
    }
    memset(&v_, 0, sizeof v_);  // all of the state is plain data; 0 is BOOT, NONE, STREAM
    Vars& v = v_;
    v.caps = robot_.capabilities;

    // 1. Configuration: the example's defaults, replaced by a good EEPROM image.
    v.cfg = robot_.default_config();
    const proto::SetPid pid = robot_.default_pid();
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        v.gains[w].kp = pid.kp;
        v.gains[w].ki = pid.ki;
        v.gains[w].kd = pid.kd;
        v.gains[w].kf = pid.kf;
    }
    config::LoadResult loaded = config::LoadResult::OK;
    uint32_t boots = 0;
    if (has(proto::Capability::EEPROM)) {
        loaded = config::load(board_, v.cfg, v.gains, link_.scratch());
        v.config_defaults = loaded != config::LoadResult::OK;
        boots = config::bump_boot_counter(board_);
    }
    apply_config(v.cfg);

    // 2. boot_id: the EEPROM boot counter mixed with the board's noise and the clock; never 0.
    uint32_t id = mix32(boots ^ 0x9E3779B9UL);
    for (uint8_t i = 0; i < 5; ++i) {
        id = mix32(id ^ (i < 4 ? board_.entropy() : board_.micros()));
    }
    v.boot_id = id != 0 ? id : 1;

    // Clocks, counts and the session values in force before any HELLO.
    const uint32_t now = clock();
    v.boot_us = now;
    v.next_tick_us = now + control::TICK_US;
    int32_t raw[proto::WHEEL_COUNT];
    board_.read_encoders(raw);
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        v.wheels[w].count = invert_if(raw[w], (v.cfg.encoder_invert >> w) & 1u);
    }
    v.watchdog_ms = v.cfg.watchdog_ms;
    v.feedback_hz = v.cfg.feedback_hz;
    v.esc_ready = !has(proto::Capability::ESC) || v.cfg.esc_arm_ms == 0;

    // 3. INIT_DONE: motors safe, boot IDENTITY. Then the LOG about the config, if any.
    fire(SessionEvent::INIT_DONE, 0, FailsafeReason::NONE);
    if (loaded != config::LoadResult::OK) {
        const char* text = loaded == config::LoadResult::NO_IMAGE
                               ? LOG_NO_IMAGE
                               : (loaded == config::LoadResult::BAD_CRC ? LOG_BAD_CRC : LOG_INVALID);
        log(proto::LogLevel::WARN, text, 0, false);
    }
    if (has(proto::Capability::TURN_SIGNALS)) {
        v.lights = control::lights_for(v.state, 0, 0, 0, false, 0);
        board_.lights(v.lights);
    }
}

// ------------------------------------------------------------------------------------------------
// Loop

uint32_t Firmware::clock() {
    const uint32_t now = board_.micros();
    if (now < v_.last_micros) {
        ++v_.micros_wraps;
    }
    v_.last_micros = now;
    return now;
}

void Firmware::poll() {
    if (v_.state == proto::INITIAL_STATE) {
        return;  // begin() has not run
    }
    receive();
    const uint32_t now = clock();
    const uint32_t late = now - v_.next_tick_us;
    if (late >= 0x80000000UL) {
        return;  // the next tick is still ahead
    }
    // If poll() came more than a whole period late: run one tick now, skip the ones missed, and stay
    // on the original grid (no drift). The speed measurement spans all the periods.
    uint16_t skipped = 0;
    for (uint32_t behind = late; behind >= control::TICK_US; behind -= control::TICK_US) {
        v_.next_tick_us += control::TICK_US;
        if (skipped < 0xFFFEu) {
            ++skipped;
        }
    }
    if (skipped != 0) {
        v_.ticks_skipped += skipped;
        if (v_.late_holdoff == 0) {
            log(proto::LogLevel::WARN, LOG_LATE, skipped, true);
            v_.late_holdoff = LATE_LOG_HOLDOFF_TICKS;
        }
    }
    v_.next_tick_us += control::TICK_US;
    control_tick(static_cast<uint16_t>(skipped + 1u), now);
}

void Firmware::receive() {
    // Only the bytes already there: a host that keeps sending cannot starve the control tick.
    int n = port_.available();
    FrameDecoder& decoder = link_.decoder();
    while (n-- > 0) {
        const int c = port_.read();
        if (c < 0) {
            break;
        }
        if (decoder.push(static_cast<uint8_t>(c)) != FrameDecoder::FRAME) {
            continue;
        }
        Rx rx = {*this};
        const uint8_t seq = decoder.seq();
        const proto::DispatchResult r =
            proto::dispatch_host_to_mcu(decoder.msg_id(), seq, decoder.payload(), decoder.payload_len(), rx);
        if (r == proto::DISPATCH_BAD_PAYLOAD) {
            decoder.reject_payload();  // not a valid frame: no seq accounting, no watchdog
        } else if (r == proto::DISPATCH_WRONG_DIRECTION) {
            on_valid_frame(seq);       // valid, counted, then ignored (docs/control.md 1.3)
        }
    }
}

// ------------------------------------------------------------------------------------------------
// Session: every state change goes through the generated table.

// Fires `ev`; performs the row's generic actions and returns all its action bits, so the caller
// does the message-specific ones (ACCEPT_HELLO, APPLY_SETPOINT). 0: no row, nothing happened.
uint16_t Firmware::fire(SessionEvent ev, uint8_t guard_bits, FailsafeReason reason) {
    Guards guards = {guard_bits};
    const proto::StepResult r = proto::step(v_.state, ev, guards);
    if (!r.matched) {
        return 0;
    }
    const SessionState from = v_.state;
    v_.state = r.target;
    const uint16_t a = r.actions;
    if (a & proto::Action::MOTORS_SAFE) {
        motors_safe();
    }
    if (a & proto::Action::CLEAR_REASON) {
        v_.reason = FailsafeReason::NONE;
        v_.encoder_fault = false;
    }
    if (a & proto::Action::LATCH_REASON) {
        v_.reason = reason;
    }
    if (a & proto::Action::FEED_WATCHDOG) {
        v_.last_valid_us = board_.micros();
    }
    if (a & proto::Action::MOTORS_ENABLE) {
        for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
            v_.wheels[w].stalled = 0;
        }
    }
    if (a & proto::Action::ANNOUNCE) {
        send_identity(proto::IdentityReason::BOOT);
    }
    if (a & proto::Action::REJECT_HELLO) {
        v_.fb_countdown = 0;
        send_identity(proto::IdentityReason::HELLO_REJECTED);
    }
    if (a & proto::Action::ACK) {
        answer(0, 0);
    }
    if (a & proto::Action::NACK) {
        // "The reason for this state" (docs/control.md 1 and 3).
        NackReason why = NackReason::NO_SESSION;
        uint8_t detail = 0;
        if (from != SessionState::IDLE) {
            if (ev == SessionEvent::ARM) {
                why = NackReason::BOOT_ID_MISMATCH;
            } else if (from == SessionState::FAILSAFE) {
                why = NackReason::FAILSAFE;
                detail = static_cast<uint8_t>(v_.reason);
            } else {
                why = NackReason::NOT_ARMED;
            }
        }
        if (ev == SessionEvent::SETPOINT) {
            send_answer(static_cast<uint8_t>(why), detail);  // setpoints are not reliable: not remembered
        } else {
            answer(static_cast<uint8_t>(why), detail);
        }
    }
    return a;
}

void Firmware::on_valid_frame(uint8_t seq) {
    link_.account_seq(seq);
    fire(SessionEvent::VALID_FRAME, 0, FailsafeReason::NONE);
}

// The common start of every message: seq accounting, VALID_FRAME, then for reliable requests the
// duplicate rule (docs/control.md 2) and NO_SESSION in IDLE. False: already answered, stop.
bool Firmware::request(uint8_t msg_id, uint8_t seq, Kind kind) {
    on_valid_frame(seq);
    Vars& v = v_;
    v.req_id = msg_id;
    v.req_seq = seq;
    if (kind == PLAIN) {
        return true;
    }
    if (v.dup_valid && v.dup_id == msg_id && v.dup_seq == seq) {
        ++v.duplicates;
        if (kind != QUERY) {
            send_answer(v.dup_reason, v.dup_detail);  // answered again, not applied again
            return false;
        }
    } else {
        v.dup_valid = true;
        v.dup_id = msg_id;
        v.dup_seq = seq;
        v.dup_reason = 0;
        v.dup_detail = 0;
    }
    if (kind != TABLE && v.state == SessionState::IDLE) {
        answer(static_cast<uint8_t>(NackReason::NO_SESSION), 0);
        return false;
    }
    return true;
}

void Firmware::answer(uint8_t reason, uint8_t detail) {
    v_.dup_reason = reason;
    v_.dup_detail = detail;
    send_answer(reason, detail);
}

void Firmware::send_answer(uint8_t reason, uint8_t detail) {
    if (reason == 0) {
        const proto::Ack ack = {v_.req_id, v_.req_seq};
        link_.send(ack);
    } else {
        const proto::Nack nack = {v_.req_id, v_.req_seq, static_cast<NackReason>(reason), detail};
        link_.send(nack);
    }
}

void Firmware::send_identity(proto::IdentityReason reason) {
    const Vars& v = v_;
    proto::Identity m = proto::Identity();  // zeroed: a field added to the spec is never garbage
    m.protocol_version = proto::PROTOCOL_VERSION;
    m.spec_hash = proto::SPEC_HASH;
    m.firmware_version[0] = FIRMWARE_VERSION.major;
    m.firmware_version[1] = FIRMWARE_VERSION.minor;
    m.firmware_version[2] = FIRMWARE_VERSION.patch;
    m.board = robot_.board;
    m.capabilities = v.caps;
    m.boot_id = v.boot_id;
    const uint32_t now = clock();
    m.uptime_ms = v.micros_wraps * MS_PER_MICROS_WRAP + now / 1000u;
    m.reason = reason;
    // Granted values; outside a session, those in force in IDLE (stream at the config's rate).
    const bool session = reason == proto::IdentityReason::HELLO_ACCEPTED;
    m.hello_seq = reason == proto::IdentityReason::BOOT ? 0 : v.req_seq;
    m.watchdog_ms = session ? v.watchdog_ms : v.cfg.watchdog_ms;
    m.feedback_mode = session ? v.mode : proto::FeedbackMode::STREAM;
    m.feedback_hz = session ? v.feedback_hz : v.cfg.feedback_hz;
    uint8_t n = 0;
    const char* name = robot_.name;
    while (name != 0 && n < sizeof m.robot_name && name[n] != '\0') {
        m.robot_name[n] = name[n];
        ++n;
    }
    m.robot_name_len = n;
    link_.send(m);
}

void Firmware::accept_hello(const proto::Hello& h) {
    Vars& v = v_;
    uint16_t wd = h.watchdog_ms != 0 ? h.watchdog_ms : v.cfg.watchdog_ms;
    if (wd == 0) {
        wd = proto::WATCHDOG_DEFAULT_MS;
    }
    v.watchdog_ms = wd < proto::WATCHDOG_MIN_MS ? proto::WATCHDOG_MIN_MS
                                                 : (wd > proto::WATCHDOG_MAX_MS ? proto::WATCHDOG_MAX_MS : wd);
    v.mode = h.feedback_mode;
    uint8_t hz = h.feedback_hz != 0 ? h.feedback_hz : v.cfg.feedback_hz;
    if (hz == 0) {
        hz = proto::FEEDBACK_HZ_DEFAULT;
    }
    v.feedback_hz = hz > proto::FEEDBACK_HZ_MAX ? proto::FEEDBACK_HZ_MAX : hz;
    v.dup_valid = false;
    link_.restart_seq();
    v.fb_countdown = 0;
    send_identity(proto::IdentityReason::HELLO_ACCEPTED);
}

void Firmware::motors_safe() {
    bool ramping = false;
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        Wheel& wh = v_.wheels[w];
        wh.target = 0;
        wh.integral = 0.0f;
        if (v_.cfg.safe_state != proto::SafeState::RAMP_DOWN) {
            wh.ramp = 0;
        }
        ramping = ramping || wh.ramp != 0;
    }
    v_.has_pending = false;
    v_.steer_mrad = 0;
    // Now, not at the next tick. RAMP_DOWN keeps driving (and steering straight) until the ramp
    // reaches zero; write_outputs() with drive on re-sends the current efforts.
    write_outputs(ramping);
}

void Firmware::setpoint(int16_t left, int16_t right, int16_t steer_mrad, uint8_t bad_field, uint16_t capability) {
    if (!has(capability)) {
        send_answer(static_cast<uint8_t>(NackReason::UNSUPPORTED), 0);
        return;
    }
    if (fire(SessionEvent::SETPOINT, 0, FailsafeReason::NONE) & proto::Action::APPLY_SETPOINT) {
        if (bad_field != proto::ALL_FIELDS_VALID) {
            send_answer(static_cast<uint8_t>(NackReason::OUT_OF_RANGE), bad_field);
            return;
        }
        v_.pending[0] = left;
        v_.pending[1] = right;
        v_.pending_steer = steer_mrad;
        v_.pending_seq = v_.req_seq;
        v_.has_pending = true;  // latest wins; the next tick applies it
    }
}

void Firmware::apply_config(const proto::SetConfig& c) {
    Vars& v = v_;
    // Keep each wheel's count continuous across an encoder_invert change: the next tick's delta
    // must not see the sign flip (the cumulative count itself does flip).
    const uint8_t flipped = static_cast<uint8_t>(v.cfg.encoder_invert ^ c.encoder_invert);
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        if ((flipped >> w) & 1u) {
            v.wheels[w].count = invert_if(v.wheels[w].count, true);
        }
    }
    v.cfg = c;
    v.mm_s_per_count = control::mm_s_per_count(c);
    v.max_effort = static_cast<float>(c.max_effort_permille);
}

void Firmware::log(proto::LogLevel level, const char* flash_text, uint32_t number, bool with_number) {
    uint8_t* p = link_.payload_slot();
    const uint8_t cap = proto::Log::PAYLOAD_MAX;
    uint8_t n = 0;
    p[n++] = static_cast<uint8_t>(level);
    for (const char* s = flash_text; n < cap; ++s) {
        const uint8_t c = static_cast<uint8_t>(ROVERLINK_READ_BYTE(s));
        if (c == 0) {
            break;
        }
        p[n++] = c;
    }
    if (with_number) {
        char digits[10];
        uint8_t k = 0;
        do {
            digits[k++] = static_cast<char>('0' + number % 10u);
            number /= 10u;
        } while (number != 0 && k < sizeof digits);
        while (k > 0 && n < cap) {
            p[n++] = static_cast<uint8_t>(digits[--k]);
        }
    }
    link_.send_payload(proto::Log::ID, proto::Log::CRC_EXTRA, n);
}

// ------------------------------------------------------------------------------------------------
// Messages

void Firmware::on_message(const proto::Hello& m, uint8_t seq) {
    request(proto::Hello::ID, seq, PLAIN);
    const bool compatible = m.protocol_version == proto::PROTOCOL_VERSION && m.spec_hash == proto::SPEC_HASH;
    if (fire(SessionEvent::HELLO, compatible ? G_COMPATIBLE : 0, FailsafeReason::NONE) & proto::Action::ACCEPT_HELLO) {
        accept_hello(m);
    }
}

void Firmware::on_message(const proto::Ping& m, uint8_t seq) {
    request(proto::Ping::ID, seq, PLAIN);
    proto::Pong pong;
    pong.host_time_us = m.host_time_us;
    pong.mcu_time_us = board_.micros();
    link_.send(pong);
}

void Firmware::on_message(const proto::Arm& m, uint8_t seq) {
    if (request(proto::Arm::ID, seq, TABLE)) {
        fire(SessionEvent::ARM, m.boot_id == v_.boot_id ? G_BOOT_ID : 0, FailsafeReason::NONE);
    }
}

void Firmware::on_message(const proto::Disarm&, uint8_t seq) {
    if (request(proto::Disarm::ID, seq, TABLE)) {
        fire(SessionEvent::DISARM, 0, FailsafeReason::NONE);
    }
}

void Firmware::on_message(const proto::SetPid& m, uint8_t seq) {
    if (!request(proto::SetPid::ID, seq, RELIABLE)) {
        return;
    }
    const bool all = m.wheel == proto::PID_ALL_WHEELS;
    if (m.wheel >= proto::WHEEL_COUNT && !all) {
        answer(static_cast<uint8_t>(NackReason::OUT_OF_RANGE), 0);
        return;
    }
    const uint8_t bad = proto::check_ranges(m);
    if (bad != proto::ALL_FIELDS_VALID) {
        answer(static_cast<uint8_t>(NackReason::OUT_OF_RANGE), bad);
        return;
    }
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        if (all || m.wheel == w) {
            control::Gains& g = v_.gains[w];
            g.kp = m.kp;
            g.ki = m.ki;
            g.kd = m.kd;
            g.kf = m.kf;
            v_.wheels[w].integral = 0.0f;
        }
    }
    answer(0, 0);
}

void Firmware::on_message(const proto::GetPid& m, uint8_t seq) {
    if (!request(proto::GetPid::ID, seq, QUERY)) {
        return;
    }
    if (m.wheel >= proto::WHEEL_COUNT) {
        answer(static_cast<uint8_t>(NackReason::OUT_OF_RANGE), 0);
        return;
    }
    // PID = req_seq followed by exactly the SET_PID fields: packed in place, no struct copy.
    static_assert(proto::Pid::PAYLOAD_SIZE == 1 + proto::SetPid::PAYLOAD_SIZE, "PID must be req_seq + SET_PID");
    const control::Gains& g = v_.gains[m.wheel];
    const proto::SetPid p = {m.wheel, g.kp, g.ki, g.kd, g.kf};
    uint8_t* out = link_.payload_slot();
    out[0] = seq;
    link_.send_payload(proto::Pid::ID, proto::Pid::CRC_EXTRA, static_cast<uint8_t>(1 + proto::pack(p, out + 1)));
}

void Firmware::on_message(const proto::SetConfig& m, uint8_t seq) {
    if (!request(proto::SetConfig::ID, seq, RELIABLE)) {
        return;
    }
    NackReason why;
    uint8_t detail;
    if (!config::validate(m, why, detail)) {
        answer(static_cast<uint8_t>(why), detail);
        return;
    }
    apply_config(m);
    answer(0, 0);
}

void Firmware::on_message(const proto::GetConfig&, uint8_t seq) {
    if (!request(proto::GetConfig::ID, seq, QUERY)) {
        return;
    }
    // CONFIG = req_seq followed by exactly the SET_CONFIG fields: packed in place.
    static_assert(proto::Config::PAYLOAD_SIZE == 1 + proto::SetConfig::PAYLOAD_SIZE,
                  "CONFIG must be req_seq + SET_CONFIG");
    uint8_t* out = link_.payload_slot();
    out[0] = seq;
    link_.send_payload(proto::Config::ID, proto::Config::CRC_EXTRA,
                       static_cast<uint8_t>(1 + proto::pack(v_.cfg, out + 1)));
}

void Firmware::on_message(const proto::SaveConfig&, uint8_t seq) {
    if (!request(proto::SaveConfig::ID, seq, RELIABLE)) {
        return;
    }
    NackReason why = NackReason::ARMED;
    if (v_.state != SessionState::ARMED) {
        why = NackReason::UNSUPPORTED;
        if (has(proto::Capability::EEPROM)) {
            why = NackReason::EEPROM_ERROR;
            v_.late_holdoff = LATE_LOG_HOLDOFF_TICKS;  // the EEPROM stall is expected: no "late" LOG
            if (config::save(board_, v_.cfg, v_.gains, link_.scratch())) {
                v_.config_defaults = false;
                answer(0, 0);
                return;
            }
        }
    }
    answer(static_cast<uint8_t>(why), 0);
}

void Firmware::on_message(const proto::ResetOdometry&, uint8_t seq) {
    if (!request(proto::ResetOdometry::ID, seq, RELIABLE)) {
        return;
    }
    board_.zero_encoders();  // the Board does it with interrupts off
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        v_.wheels[w].count = 0;
    }
    answer(0, 0);
}

void Firmware::on_message(const proto::GetLinkStats&, uint8_t seq) {
    if (!request(proto::GetLinkStats::ID, seq, QUERY)) {
        return;
    }
    const DecoderStats& d = link_.decoder().stats();
    proto::LinkStats s = proto::LinkStats();
    s.req_seq = seq;
    s.frames_ok = d.frames_ok;
    s.crc_errors = d.crc_errors;
    s.cobs_errors = d.cobs_errors;
    s.length_errors = d.length_errors;
    s.unknown_ids = d.unknown_ids;
    s.value_errors = d.value_errors;
    s.seq_gaps = link_.seq_gaps();
    s.bytes_discarded = d.bytes_discarded;
    s.rx_overruns = 0;  // the Arduino core drops UART overruns silently: not observable here
    s.duplicates = v_.duplicates;
    s.frames_sent = link_.frames_sent();
    link_.send(s);
}

void Firmware::on_message(const proto::SetWheelSpeeds& m, uint8_t seq) {
    request(proto::SetWheelSpeeds::ID, seq, PLAIN);
    setpoint(m.left_mm_s, m.right_mm_s, 0,
             checked_speed(m.left_mm_s, m.right_mm_s, v_.cfg.max_wheel_speed_mm_s, proto::check_ranges(m)),
             proto::Capability::DIFF_DRIVE);
}

void Firmware::on_message(const proto::SetAckermann& m, uint8_t seq) {
    request(proto::SetAckermann::ID, seq, PLAIN);
    setpoint(m.speed_mm_s, 0, m.steering_mrad,
             checked_speed(m.speed_mm_s, 0, v_.cfg.max_wheel_speed_mm_s, proto::check_ranges(m)),
             proto::Capability::ACKERMANN);
}

// ------------------------------------------------------------------------------------------------
// Control tick (docs/control.md 4)

uint8_t Firmware::driven_wheels() const { return has(proto::Capability::DIFF_DRIVE) ? proto::WHEEL_COUNT : 1; }

void Firmware::control_tick(uint16_t periods, uint32_t now) {
    Vars& v = v_;
    ++v.tick;
    if (v.late_holdoff != 0) {
        --v.late_holdoff;
    }

    // 1. Sample: one atomic copy of the counts (the Board's job), encoder_invert; 2. measure.
    int32_t raw[proto::WHEEL_COUNT];
    board_.read_encoders(raw);
    int32_t delta[proto::WHEEL_COUNT];
    int16_t m_prev[proto::WHEEL_COUNT];
    const bool encoders = has(proto::Capability::ENCODERS);
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        Wheel& wh = v.wheels[w];
        const int32_t c = invert_if(raw[w], (v.cfg.encoder_invert >> w) & 1u);
        delta[w] = static_cast<int32_t>(static_cast<uint32_t>(c) - static_cast<uint32_t>(wh.count));
        wh.count = c;
        m_prev[w] = wh.measured;
        wh.measured = encoders ? control::measure_speed(delta[w], v.mm_s_per_count, periods) : 0;
    }

    // 3. Watchdog: FAILSAFE in this tick, at most one tick after expiry.
    if (v.state == SessionState::ARMED && now - v.last_valid_us >= static_cast<uint32_t>(v.watchdog_ms) * 1000u) {
        fire(SessionEvent::WATCHDOG_EXPIRED, 0, FailsafeReason::COMM_TIMEOUT);
    }

    // 4. The latest setpoint, if one arrived (only ever stored while ARMED).
    const bool armed = v.state == SessionState::ARMED;
    bool applied = false;
    if (v.has_pending && armed) {
        for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
            v.wheels[w].target = v.pending[w];
        }
        v.steer_mrad = v.pending_steer;
        v.ack_seq = v.pending_seq;
        v.ack_tick = v.tick;
        applied = true;
    }
    v.has_pending = false;

    // The ESC's arming window: neutral only, the loop held at rest, until esc_arm_ms after boot.
    if (!v.esc_ready && now - v.boot_us >= static_cast<uint32_t>(v.cfg.esc_arm_ms) * 1000u) {
        v.esc_ready = true;
    }

    // 5.-6. Ramp and PID.
    const bool hold = !v.esc_ready || (!armed && v.cfg.safe_state != proto::SafeState::RAMP_DOWN);
    bool ramping = false;
    v.saturated = false;
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        Wheel& wh = v.wheels[w];
        if (hold) {
            wh.ramp = 0;  // at rest (also covers a safe_state change in the middle of a ramp)
        } else {
            wh.ramp = control::ramp_step(wh.ramp, static_cast<int32_t>(wh.target) * control::RAMP_UNITS_PER_MM_S,
                                         v.cfg.accel_limit_mm_s2, v.cfg.decel_limit_mm_s2);
        }
        if ((wh.target == 0 || !v.esc_ready) && wh.ramp == 0) {
            wh.effort = 0;  // standstill: no hum
            wh.integral = 0.0f;
            continue;
        }
        ramping = true;
        bool sat = false;
        const float r = static_cast<float>(wh.ramp) * (1.0f / control::RAMP_UNITS_PER_MM_S);
        if (encoders) {
            wh.effort = control::pid_step(v.gains[w], r, wh.measured, m_prev[w], v.max_effort, wh.integral, sat);
        } else {
            // Open loop (no encoder to close it on): feed-forward only.
            const control::Gains ff = {0.0f, 0.0f, 0.0f, v.gains[w].kf};
            wh.integral = 0.0f;
            wh.effort = control::pid_step(ff, r, 0, 0, v.max_effort, wh.integral, sat);
        }
        v.saturated = v.saturated || sat;
    }

    // 7. Outputs. Out of ARMED, RAMP_DOWN drives until every ramped speed is 0, then coasts.
    write_outputs(armed || ramping);

    // 8. Encoder fault: |u| >= 300 for 50 ticks while the count does not move.
    if (encoders) {
        bool fault = false;
        for (uint8_t w = 0; w < driven_wheels(); ++w) {
            Wheel& wh = v.wheels[w];
            if (abs16(wh.effort) >= STALL_EFFORT && delta[w] == 0) {
                if (wh.stalled < STALL_TICKS) {
                    ++wh.stalled;
                }
                fault = fault || wh.stalled >= STALL_TICKS;
            } else {
                wh.stalled = 0;
            }
        }
        if (fault) {
            v.encoder_fault = true;
            fire(SessionEvent::FAULT, 0, FailsafeReason::ENCODER_FAULT);
        }
    }

    // Lights from the motion state, blinking from the tick counter.
    if (has(proto::Capability::TURN_SIGNALS)) {
        const uint8_t mask =
            control::lights_for(v.state, v.wheels[0].target, v.wheels[1].target,
                                static_cast<int16_t>(v.servo_cdeg - v.cfg.steering_center_cdeg),
                                has(proto::Capability::ACKERMANN), v.blink);
        if (mask != v.lights) {
            v.lights = mask;
            board_.lights(mask);
        }
    }
    if (++v.blink >= control::BLINK_PERIOD_TICKS) {
        v.blink = 0;
    }

    // 9. Feedback: stream (always in IDLE) on a countdown; lockstep once per applied setpoint.
    bool send = applied;
    if (feedback_mode() == proto::FeedbackMode::STREAM) {
        send = v.fb_countdown == 0;
        if (send) {
            // round(CONTROL_RATE_HZ / hz), half up, in 8 bits: floor((floor(2 * 100 / hz) + 1) / 2).
            static_assert(2 * proto::CONTROL_RATE_HZ <= 255, "the stream period is computed in 8 bits");
            const uint8_t hz = feedback_hz();
            const uint8_t twice = static_cast<uint8_t>(2 * proto::CONTROL_RATE_HZ);
            v.fb_countdown = static_cast<uint8_t>((hz != 0 ? twice / hz + 1u : 2u) / 2u - 1u);
        } else {
            --v.fb_countdown;
        }
    }
    if (send) {
        send_feedback(now);
    }
}

void Firmware::write_outputs(bool drive) {
    const Vars& v = v_;
    const MotorMode safe = v.cfg.safe_state == proto::SafeState::BRAKE ? MotorMode::BRAKE : MotorMode::COAST;
    const uint8_t n = driven_wheels();
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        Wheel& wh = v_.wheels[w];
        if (!drive) {
            wh.effort = 0;
        }
        if (w >= n) {
            continue;
        }
        const int16_t u = ((v.cfg.motor_invert >> w) & 1u) ? static_cast<int16_t>(-wh.effort) : wh.effort;
        if (w == 0 && has(proto::Capability::ESC)) {
            board_.esc_pulse(control::esc_pulse_us(drive && v.esc_ready ? u : 0, v.cfg));
        } else {
            board_.drive(w, drive ? u : 0, drive ? MotorMode::DRIVE : safe);
        }
    }
    v_.servo_cdeg = control::steering_cdeg(v.steer_mrad, v.cfg);
    if (has(proto::Capability::STEERING_SERVO)) {
        board_.steering_pulse(control::servo_pulse_us(v.servo_cdeg, v.cfg));
    }
}

void Firmware::send_feedback(uint32_t sample_us) {
    const Vars& v = v_;
    proto::Feedback f = proto::Feedback();
    f.boot_id = v.boot_id;
    f.mcu_time_us = sample_us;
    f.tick = v.tick;
    f.ack_seq = v.ack_seq;
    f.ack_tick = v.ack_tick;
    f.status = status();
    f.failsafe_reason = v.reason;
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        f.encoder_counts[w] = v.wheels[w].count;
        f.wheel_speed_mm_s[w] = v.wheels[w].measured;
        f.effort_permille[w] = v.wheels[w].effort;
    }
    f.steering_mrad = has(proto::Capability::STEERING_SERVO) ? control::steering_mrad(v.servo_cdeg, v.cfg) : 0;
    link_.send(f);
}

uint8_t Firmware::status() const {
    const Vars& v = v_;
    uint8_t s = 0;
    switch (v.state) {
    case SessionState::ARMED:
        s = proto::Status::SESSION | proto::Status::ARMED;
        break;
    case SessionState::FAILSAFE:
        s = proto::Status::SESSION | proto::Status::FAILSAFE;
        break;
    case SessionState::DISARMED:
        s = proto::Status::SESSION;
        break;
    default:
        break;
    }
    if (s != 0 && v.mode == proto::FeedbackMode::LOCKSTEP) {
        s |= proto::Status::LOCKSTEP;
    }
    if (v.saturated) {
        s |= proto::Status::SATURATED;
    }
    if (v.encoder_fault) {
        s |= proto::Status::ENCODER_FAULT;
    }
    if (v.config_defaults) {
        s |= proto::Status::CONFIG_DEFAULTS;
    }
    return s;
}

proto::FeedbackMode Firmware::feedback_mode() const {
    return v_.state <= SessionState::IDLE ? proto::FeedbackMode::STREAM : v_.mode;
}

uint8_t Firmware::feedback_hz() const { return v_.state <= SessionState::IDLE ? v_.cfg.feedback_hz : v_.feedback_hz; }

}  // namespace roverlink
