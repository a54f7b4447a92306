#include "firmware.h"

#include <string.h>

namespace roverlink {

using proto::FailsafeReason;
using proto::NackReason;
using proto::SessionState;

namespace {

// LOG texts live in flash (PROGMEM on AVR), never in SRAM. Each is <= 60 ASCII characters; the
// exact texts are listed in docs/firmware.md for the emulator to reproduce.
const char LOG_NO_IMAGE[] ROVERLINK_PROGMEM = "config: no EEPROM image for this version, using defaults";
const char LOG_BAD_CRC[] ROVERLINK_PROGMEM = "config: EEPROM CRC error, using defaults";
const char LOG_INVALID[] ROVERLINK_PROGMEM = "config: EEPROM values invalid, using defaults";
const char LOG_LATE[] ROVERLINK_PROGMEM = "control: poll() late, ticks skipped: ";

const uint8_t STALL_TICKS = 50;              // docs/control.md 4.8: 0.5 s ...
const int16_t STALL_EFFORT = 300;            // ... at |u| >= 300 permille without a count
const uint8_t LATE_LOG_HOLDOFF_TICKS = 100;  // at most one "late" LOG per second

int32_t invert_if(int32_t raw, bool invert) {
    // Two's complement negation without signed overflow (INT32_MIN stays INT32_MIN).
    return invert ? static_cast<int32_t>(0u - static_cast<uint32_t>(raw)) : raw;
}

int16_t abs16(int16_t x) { return x < 0 ? static_cast<int16_t>(-x) : x; }

}  // namespace

// Several functions below are ROVERLINK_NOINLINE or ROVERLINK_OUT_OF_LINE (wire/compiler.h)
// although they have one caller: inlined into the sketch's loop() (LTO), GCC addresses the global
// firmware object's members absolutely (lds/sts, four bytes each on AVR) rather than through
// `this` (two). Each mark stays where it measured smaller on the Uno; together they save ~1 KB.

// v_ is left alone here (begin() sets all of it): zeroing it costs flash for no effect.
Firmware::Firmware(Stream& port, Board& board, const Robot& robot)
    : board_(board), robot_(robot), session_(port, board, robot, *this) {}

// ------------------------------------------------------------------------------------------------
// Boot

ROVERLINK_NOINLINE void Firmware::begin() {
    if (session_.state() != proto::INITIAL_STATE) {
        return;  // begin() runs once per boot
    }
    memset(&v_, 0, sizeof v_);  // all of the state is plain data
    Vars& v = v_;
    v.caps = robot_.capabilities;
    v.lights_set.mode = robot_.lights_mode;

    // 1. Configuration: the example's defaults, replaced by a good EEPROM image.
    v.cfg = robot_.default_config();
    proto::SetPid pid = robot_.default_pid();
    pid.wheel = proto::PID_ALL_WHEELS;  // the example's gains on every wheel
    set_pid(pid);
    config::LoadResult loaded = config::LoadResult::OK;
    uint32_t boots = 0;
    if (has(proto::Capability::EEPROM)) {
        loaded = config::load(board_, v.cfg, v.gains, session_.scratch());
        v.config_defaults = loaded != config::LoadResult::OK;
        boots = config::bump_boot_counter(board_);
    }
    apply_config(v.cfg);

    // Clocks and counts.
    const uint32_t now = session_.clock();
    v.boot_us = now;
    v.next_tick_us = now + control::TICK_US;
    int32_t raw[proto::WHEEL_COUNT];
    board_.read_encoders(raw);
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        v.wheels[w].count = invert_if(raw[w], (v.cfg.encoder_invert >> w) & 1u);
    }
    v.esc_ready = !has(proto::Capability::ESC) || v.cfg.esc_arm_ms == 0;

    // 2.-3. boot_id, INIT_DONE: motors safe, boot IDENTITY. Then the LOG about the config, if any.
    session_.begin(boots);
    if (loaded != config::LoadResult::OK) {
        const char* text = loaded == config::LoadResult::NO_IMAGE
                               ? LOG_NO_IMAGE
                               : (loaded == config::LoadResult::BAD_CRC ? LOG_BAD_CRC : LOG_INVALID);
        session_.log(proto::LogLevel::WARN, text);
    }
    if (has(proto::Capability::TURN_SIGNALS)) {
        v.lights = lights_mask();
        board_.lights(v.lights);
    }
}

// ------------------------------------------------------------------------------------------------
// Loop

ROVERLINK_OUT_OF_LINE void Firmware::poll() {
    if (session_.state() == proto::INITIAL_STATE) {
        return;  // begin() has not run
    }
    session_.poll();
    const uint32_t now = session_.clock();
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
            char digits[5];  // skipped <= 65534
            uint8_t k = sizeof digits;
            for (uint16_t x = skipped; k == sizeof digits || x != 0; x /= 10u) {
                digits[--k] = static_cast<char>('0' + x % 10u);
            }
            session_.log(proto::LogLevel::WARN, LOG_LATE, digits + k, static_cast<uint8_t>(sizeof digits - k));
            v_.late_holdoff = LATE_LOG_HOLDOFF_TICKS;
        }
    }
    v_.next_tick_us += control::TICK_US;
    control_tick(static_cast<uint16_t>(skipped + 1u), now);
}

// ------------------------------------------------------------------------------------------------
// The session's App: what the state table's rows and the requests do to the robot.

ROVERLINK_NOINLINE void Firmware::session_actions(uint16_t a) {
    if (a & proto::Action::MOTORS_SAFE) {
        motors_safe();
    }
    if (a & proto::Action::CLEAR_REASON) {
        v_.encoder_fault = false;
    }
    if (a & proto::Action::ACCEPT_HELLO) {
        // A new session starts from the power-up lights: nothing of the last host's stays.
        proto::SetLights& l = v_.lights_set;
        l.mode = robot_.lights_mode;
        l.steady = l.slow = l.fast = 0;
    }
    if (a & proto::Action::MOTORS_ENABLE) {
        for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
            v_.wheels[w].stalled = 0;
        }
    }
}

uint8_t Firmware::set_config(const proto::SetConfig& c, uint8_t& detail) {
    detail = config::inconsistent_field(c);
    if (detail != proto::ALL_FIELDS_VALID) {
        return static_cast<uint8_t>(NackReason::INVALID_CONFIG);
    }
    apply_config(c);
    return 0;
}

ROVERLINK_NOINLINE void Firmware::set_pid(const proto::SetPid& m) {
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        if (m.wheel == proto::PID_ALL_WHEELS || m.wheel == w) {
            control::gains_from(v_.gains[w], m);
            v_.wheels[w].integral = 0.0f;
        }
    }
}

void Firmware::pid(uint8_t wheel, proto::SetPid& out) const {
    control::gains_to(out, v_.gains[wheel]);
}

ROVERLINK_NOINLINE uint8_t Firmware::save_config() {
    if (!has(proto::Capability::EEPROM)) {
        return static_cast<uint8_t>(NackReason::UNSUPPORTED);
    }
    v_.late_holdoff = LATE_LOG_HOLDOFF_TICKS;  // the EEPROM stall is expected: no "late" LOG
    if (!config::save(board_, v_.cfg, v_.gains, session_.scratch())) {
        return static_cast<uint8_t>(NackReason::EEPROM_ERROR);
    }
    v_.config_defaults = false;
    return 0;
}

void Firmware::reset_odometry() {
    board_.zero_encoders();  // the Board does it with interrupts off
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        v_.wheels[w].count = 0;
    }
}

// SET_LIGHTS and GET_LIGHTS (the session did NO_SESSION and duplicates).
void Firmware::request(const proto::HostToMcu& m, uint8_t id) {
    static_assert(offsetof(proto::LightsState, mode) == 1 && sizeof(proto::SetLights) == 4 &&
                      offsetof(proto::LightsState, lit) == 5,
                  "LIGHTS_STATE must be req_seq, the SET_LIGHTS fields, lit");
    uint8_t why = static_cast<uint8_t>(NackReason::UNSUPPORTED);
    uint8_t detail = 0;
    if (id == proto::SetLights::ID) {
        // Ranges first, as for every request with a value the decoder leaves to them (the
        // emulator's bad-value rule): an undefined mode is OUT_OF_RANGE on any robot.
        const uint8_t bad = proto::check_ranges(m.set_lights);  // the mode's value too (docs/codec.md)
        if (bad != proto::ALL_FIELDS_VALID) {
            why = static_cast<uint8_t>(NackReason::OUT_OF_RANGE);
            detail = bad;
        } else if (has(proto::Capability::TURN_SIGNALS)) {
            v_.lights_set = m.set_lights;  // the next tick shows it
            why = 0;
        }
    } else if (id == proto::GetLights::ID) {
        if (has(proto::Capability::TURN_SIGNALS)) {
            proto::LightsState& s = session_.out().lights_state;
            memcpy(&s.mode, &v_.lights_set, sizeof v_.lights_set);
            s.lit = v_.lights;
            session_.send_reply(proto::LightsState::ID, proto::LightsState::CRC_EXTRA,
                                proto::LightsState::PAYLOAD_SIZE - 1);
            return;
        }
    } else {
        return;  // a message added to the spec that this firmware does not handle yet
    }
    session_.answer(why, detail);
}

// The lamps of this tick: control::lights_for() over the setting in force.
uint8_t Firmware::lights_mask() const {
    const Vars& v = v_;
    return control::lights_for(v.lights_set, session_.state(), v.wheels[0].target, v.wheels[1].target,
                               static_cast<int16_t>(v.servo_cdeg - v.cfg.steering_center_cdeg),
                               has(proto::Capability::ACKERMANN), v.blink);
}

void Firmware::setpoint(int16_t left, int16_t right, int16_t steer_mrad, uint8_t seq) {
    // Stream mode: latest wins. Lockstep: a queue, so a host may stay a tick ahead and be late by
    // most of two ticks before a tick goes unanswered. Full, the newest is superseded.
    const uint8_t room = session_.feedback_mode() == proto::FeedbackMode::LOCKSTEP ? proto::LOCKSTEP_QUEUE : 1;
    const uint8_t at = v_.queued < room ? v_.queued++ : static_cast<uint8_t>(room - 1);
    Queued& q = v_.queue[at];
    q.wheel[0] = left;
    q.wheel[1] = right;
    q.steer_mrad = steer_mrad;
    q.seq = seq;
}

uint8_t Firmware::status_bits() const {
    uint8_t s = 0;
    if (v_.saturated) {
        s |= proto::Status::SATURATED;
    }
    if (v_.encoder_fault) {
        s |= proto::Status::ENCODER_FAULT;
    }
    if (v_.config_defaults) {
        s |= proto::Status::CONFIG_DEFAULTS;
    }
    return s;
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
    v_.queued = 0;
    v_.steer_mrad = 0;
    // Now, not at the next tick. RAMP_DOWN keeps driving (and steering straight) until the ramp
    // reaches zero; write_outputs() with drive on re-sends the current efforts.
    write_outputs(ramping);
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
}

// ------------------------------------------------------------------------------------------------
// Control tick (docs/control.md 4)

uint8_t Firmware::driven_wheels() const { return has(proto::Capability::DIFF_DRIVE) ? proto::WHEEL_COUNT : 1; }

ROVERLINK_OUT_OF_LINE void Firmware::control_tick(uint16_t periods, uint32_t now) {
    Vars& v = v_;
    ++v.tick;
    if (v.late_holdoff != 0) {
        --v.late_holdoff;
    }

    // 1. Sample: one atomic copy of the counts (the Board's job).
    int32_t raw[proto::WHEEL_COUNT];
    board_.read_encoders(raw);

    // 3. Watchdog: FAILSAFE in this tick, at most one tick after expiry. (Step 2, the measurement,
    // comes with each wheel below: nothing the watchdog's safe state does touches it.)
    session_.check_watchdog(now);

    // 4. The oldest waiting setpoint, if one arrived (only ever stored while ARMED), re-limited
    // every tick to the config in effect: a lowered max_wheel_speed_mm_s applies to the targets at once.
    const bool armed = session_.armed();
    bool applied = false;
    static_assert(proto::WHEEL_COUNT == 2, "one target per wheel");
    int16_t next[proto::WHEEL_COUNT] = {v.wheels[0].target, v.wheels[1].target};
    if (v.queued != 0 && armed) {
        const Queued& q = v.queue[0];
        next[0] = q.wheel[0];
        next[1] = q.wheel[1];
        v.steer_mrad = q.steer_mrad;
        v.ack_seq = q.seq;
        v.ack_tick = v.tick;
        applied = true;
        --v.queued;
        for (uint8_t i = 0; i < v.queued; ++i) {
            v.queue[i] = v.queue[i + 1];
        }
    } else {
        v.queued = 0;
    }
    control::limit_targets(next, v.cfg.max_wheel_speed_mm_s);
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        v.wheels[w].target = next[w];
    }

    // The ESC's arming window: neutral only, the loop held at rest, until esc_arm_ms after boot.
    if (!v.esc_ready && now - v.boot_us >= static_cast<uint32_t>(v.cfg.esc_arm_ms) * 1000u) {
        v.esc_ready = true;
    }

    // 2., 5.-6. and 8.'s count, wheel by wheel.
    const bool hold = !v.esc_ready || (!armed && v.cfg.safe_state != proto::SafeState::RAMP_DOWN);
    uint8_t flags = 0;
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        flags |= tick_wheel(w, raw[w], periods, hold);
    }
    v.saturated = (flags & WHEEL_SATURATED) != 0;

    // 7. Outputs. Out of ARMED, RAMP_DOWN drives until every ramped speed is 0, then coasts.
    write_outputs(armed || (flags & WHEEL_RAMPING) != 0);

    // 8. Encoder fault: |u| >= 300 for 50 ticks while the count does not move.
    if (flags & WHEEL_STALLED) {
        v.encoder_fault = true;
        session_.fault(FailsafeReason::ENCODER_FAULT);
    }

    // Lights from the motion state, blinking from the tick counter.
    if (has(proto::Capability::TURN_SIGNALS)) {
        const uint8_t mask = lights_mask();
        if (mask != v.lights) {
            v.lights = mask;
            board_.lights(mask);
        }
    }
    if (++v.blink >= control::BLINK_PERIOD_TICKS) {
        v.blink = 0;
    }

    // 9. Feedback: lockstep while ARMED once per applied setpoint; otherwise streamed on a countdown.
    if (session_.feedback_due(applied)) {
        send_feedback(now);
    }
}

// One wheel's share of the tick: measure (2), ramp (5), PID (6), and the stall count of the
// encoder fault (8). Its effort is final here: write_outputs() only zeroes efforts that already are.
uint8_t Firmware::tick_wheel(uint8_t w, int32_t raw, uint16_t periods, bool hold) {
    Vars& v = v_;
    Wheel& wh = v.wheels[w];
    const int32_t c = invert_if(raw, (v.cfg.encoder_invert >> w) & 1u);
    const int32_t delta = static_cast<int32_t>(static_cast<uint32_t>(c) - static_cast<uint32_t>(wh.count));
    wh.count = c;
    int16_t m_prev = wh.measured;
    const bool encoders = has(proto::Capability::ENCODERS);
    wh.measured = encoders ? control::measure_speed(delta, v.mm_s_per_count, periods) : 0;

    if (hold) {
        wh.ramp = 0;  // at rest (also covers a safe_state change in the middle of a ramp)
    } else {
        wh.ramp = control::ramp_step(wh.ramp, static_cast<int32_t>(wh.target) * control::RAMP_UNITS_PER_MM_S,
                                     v.cfg.accel_limit_mm_s2, v.cfg.decel_limit_mm_s2);
    }
    uint8_t flags = 0;
    if ((wh.target == 0 || !v.esc_ready) && wh.ramp == 0) {
        wh.effort = 0;  // standstill: no hum
        wh.integral = 0.0f;
    } else {
        flags = WHEEL_RAMPING;
        bool sat = false;
        const float r = static_cast<float>(wh.ramp) * (1.0f / control::RAMP_UNITS_PER_MM_S);
        const control::Gains* g = &v.gains[w];
        int16_t m = wh.measured;
        control::Gains ff;
        if (!encoders) {
            // Open loop (no encoder to close it on): feed-forward only.
            ff.kp = ff.ki = ff.kd = 0.0f;
            ff.kf = g->kf;
            ff.ks = g->ks;
            g = &ff;
            wh.integral = 0.0f;
            m = m_prev = 0;
        }
        // The limit converted here, not kept as a float: 4 B less of Firmware's SRAM.
        const float max_effort = static_cast<float>(v.cfg.max_effort_permille);
        wh.effort = control::pid_step(*g, r, m, m_prev, max_effort, wh.integral, sat);
        if (sat) {
            flags |= WHEEL_SATURATED;
        }
    }

    if (encoders && w < driven_wheels()) {
        if (abs16(wh.effort) >= STALL_EFFORT && delta == 0) {
            if (wh.stalled < STALL_TICKS) {
                ++wh.stalled;
            }
            if (wh.stalled >= STALL_TICKS) {
                flags |= WHEEL_STALLED;
            }
        } else {
            wh.stalled = 0;
        }
    }
    return flags;
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

ROVERLINK_OUT_OF_LINE void Firmware::send_feedback(uint32_t sample_us) {
    const Vars& v = v_;
    proto::Feedback f = proto::Feedback();
    f.mcu_time_us = sample_us;
    f.tick = v.tick;
    f.ack_seq = v.ack_seq;
    f.ack_tick = v.ack_tick;
    for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
        f.encoder_counts[w] = v.wheels[w].count;
        f.wheel_speed_mm_s[w] = v.wheels[w].measured;
        f.effort_permille[w] = v.wheels[w].effort;
    }
    f.steering_mrad = has(proto::Capability::STEERING_SERVO) ? control::steering_mrad(v.servo_cdeg, v.cfg) : 0;
    session_.send_feedback(f);  // + boot_id, status, failsafe_reason
}

}  // namespace roverlink
