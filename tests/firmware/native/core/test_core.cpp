// Native tests of the RoverLink firmware core (arduino/RoverLink/src/core) against docs/control.md.
// Plain C++, built plain and with AddressSanitizer + UBSan (`make -C tests/firmware/native core-test`); the
// last line reads "N passed, M failed". Host frames are built with the generated structs and the
// C++ codec; replies are decoded the same way.
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <set>
#include <string>
#include <vector>

#include <RoverLink.h>

#include "harness.h"
#include "profiles.h"
#include "sim.h"

using namespace roverlink;
using namespace harness;
using proto::FailsafeReason;
using proto::FeedbackMode;
using proto::NackReason;
using proto::SessionState;

namespace harness {
unsigned g_passed = 0;
unsigned g_failed = 0;
char g_ctx[200] = "";
}  // namespace harness

// The C ABI of sim_api.cpp, linked into this binary so the sanitizers cover it too.
extern "C" {
struct rl_sim;
struct rl_sim_outputs;
rl_sim* rl_sim_create(const char* profile, uint32_t seed);
void rl_sim_destroy(rl_sim*);
void rl_sim_reset(rl_sim*);
void rl_sim_feed_host_bytes(rl_sim*, const uint8_t*, size_t);
size_t rl_sim_read_mcu_bytes(rl_sim*, uint8_t*, size_t);
void rl_sim_advance_us(rl_sim*, uint64_t);
void rl_sim_add_encoder(rl_sim*, uint8_t, int32_t);
void rl_sim_get_outputs(rl_sim*, rl_sim_outputs*);
uint32_t rl_sim_outputs_size(void);
int rl_sim_profile_count(void);
const char* rl_sim_profile_name(int);
int rl_sim_eeprom_read(rl_sim*, uint32_t, uint8_t*, uint32_t);
int rl_sim_eeprom_write(rl_sim*, uint32_t, const uint8_t*, uint32_t);
}

// -------------------------------------------------------------------------------------------------
// Helpers

static const Robot& TB6612 = sim_profiles::DIFFDRIVE_TB6612;
static const Robot& BTS7960 = sim_profiles::DIFFDRIVE_BTS7960;
static const Robot& PICAR = sim_profiles::PICAR;

static proto::Hello hello(FeedbackMode mode = FeedbackMode::STREAM, uint8_t hz = 0, uint16_t watchdog_ms = 0) {
    proto::Hello h;
    h.protocol_version = proto::PROTOCOL_VERSION;
    h.spec_hash = proto::SPEC_HASH;
    h.watchdog_ms = watchdog_ms;
    h.feedback_mode = mode;
    h.feedback_hz = hz;
    return h;
}

static proto::SetWheelSpeeds wheels(int16_t l, int16_t r) {
    proto::SetWheelSpeeds m;
    m.left_mm_s = l;
    m.right_mm_s = r;
    return m;
}

static proto::SetAckermann ackermann(int16_t speed, int16_t mrad) {
    proto::SetAckermann m;
    m.speed_mm_s = speed;
    m.steering_mrad = mrad;
    return m;
}

static proto::Arm arm_msg(uint32_t boot_id) {
    proto::Arm a;
    a.boot_id = boot_id;
    return a;
}

static proto::SetConfig config_of(const Sim& s) {
    return s.fw->config();
}

// Did the last frame answer (id, seq) with an ACK?
static bool acked(const Host& h, uint8_t id, uint8_t seq) {
    proto::Ack a;
    return h.last(a) && a.req_id == id && a.req_seq == seq;
}

static bool nacked(const Host& h, uint8_t id, uint8_t seq, NackReason why, int detail = -1) {
    proto::Nack n;
    return h.last(n) && n.req_id == id && n.req_seq == seq && n.reason == why && (detail < 0 || n.detail == detail);
}

// The last frame received, whatever it is.
static uint8_t last_id(const Host& h) { return h.frames.empty() ? 0 : h.frames.back().id; }

// Zero gains: effort stays 0, so tests without a plant never trip the encoder-fault check.
static void quiet_pid(Host& h) {
    proto::SetPid p = {proto::PID_ALL_WHEELS, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    h.send(p);
    h.run();
}

static void open_session(Host& h, FeedbackMode mode = FeedbackMode::STREAM, uint8_t hz = 0, uint16_t wd = 0) {
    h.send(hello(mode, hz, wd));
    h.run();
}

static void open_and_arm(Sim& s, Host& h, FeedbackMode mode = FeedbackMode::STREAM, uint8_t hz = 0,
                         uint16_t wd = 0) {
    open_session(h, mode, hz, wd);
    h.send(arm_msg(s.fw->boot_id()));
    h.run();
}

// First-order DC motor + wheel + quadrature encoder, in the Board's raw terms (driver effort in,
// raw counts out), so the firmware's motor_invert and encoder_invert cancel as on a real robot.
struct Plant {
    double speed_mm_s;
    double position_counts;
    double gain_mm_s;  // steady speed at full effort
    double tau_s;
    double counts_per_mm;

    explicit Plant(const proto::SetConfig& c, double gain = 700.0, double tau = 0.08)
        : speed_mm_s(0), position_counts(0), gain_mm_s(gain), tau_s(tau),
          counts_per_mm(c.encoder_cpr / (M_PI * c.wheel_diameter_um / 1000.0)) {}

    void step(double effort_permille, double dt) {
        speed_mm_s += (gain_mm_s * effort_permille / 1000.0 - speed_mm_s) * dt / tau_s;
        position_counts += speed_mm_s * dt * counts_per_mm;
    }
    int32_t counts() const { return static_cast<int32_t>(floor(position_counts)); }
};

// The effort the board is putting out on a wheel: a DC driver's DRIVE effort, or the ESC pulse
// turned back into permille.
static double board_effort(const Sim& s, uint8_t w) {
    if (w == 0 && (s.robot.capabilities & proto::Capability::ESC)) {
        const proto::SetConfig c = s.fw->config();
        const int us = s.board.esc_us();
        if (us == 0) {
            return 0;
        }
        return us >= c.esc_neutral_us ? 1000.0 * (us - c.esc_neutral_us) / (c.esc_max_us - c.esc_neutral_us)
                                      : 1000.0 * (us - c.esc_neutral_us) / (c.esc_neutral_us - c.esc_min_us);
    }
    const NativeBoard::Motor& m = s.board.motor(w);
    return m.mode == MotorMode::DRIVE ? m.effort : 0.0;
}

// Runs the plant and the firmware for `ms` milliseconds in 1 ms steps. `keepalive` re-sends the
// setpoint every 50 ms (the watchdog is 250 ms by default).
template <class Setpoint>
static void run_plant(Sim& s, Host& h, Plant* plants, uint8_t nplants, uint32_t ms, const Setpoint* keepalive,
                      std::vector<double>* trace0 = 0) {
    for (uint32_t t = 0; t < ms; ++t) {
        if (keepalive != 0 && t % 50 == 0) {
            h.send(*keepalive);
        }
        for (uint8_t w = 0; w < nplants; ++w) {
            plants[w].step(board_effort(s, w), 0.001);
            s.board.set_encoder(w, plants[w].counts());
        }
        s.advance_us(1000);
        if (trace0 != 0) {
            trace0->push_back(plants[0].speed_mm_s);
        }
    }
    h.pump();
}

// -------------------------------------------------------------------------------------------------
// Control math (pure functions)

static void test_rounding() {
    CONTEXT("rounding");
    CHECK_EQ(control::round_half_away(0.5f), 1);
    CHECK_EQ(control::round_half_away(-0.5f), -1);
    CHECK_EQ(control::round_half_away(1.49f), 1);
    CHECK_EQ(control::round_half_away(-2.5f), -3);
    CHECK_EQ(control::round_half_away(0.0f), 0);
    CHECK_EQ(control::round_to_i16(1e9f), 32767);
    CHECK_EQ(control::round_to_i16(-1e9f), -32768);
    CHECK_EQ(control::round_to_i16(NAN), 0);
    CHECK_EQ(control::div_round(750, 1500), 1);
    CHECK_EQ(control::div_round(-750, 1500), -1);
    CHECK_EQ(control::div_round(749, 1500), 0);
    CHECK_EQ(control::div_round(-749, 1500), 0);
    CHECK_EQ(control::div_round(2, 3), 1);
    CHECK_EQ(control::div_round(-2, 3), -1);
    CHECK_EQ(control::div_round(100, 30), 3);   // 30 Hz stream: every 3 ticks
    CHECK_EQ(control::div_round(100, 40), 3);   // 2.5 rounds away from zero
}

static void test_ramp_math() {
    CONTEXT("ramp_step (0.01 mm/s units; limits in mm/s^2 are the per-tick steps)");
    CHECK_EQ(control::ramp_step(0, 30000, 1000, 2000), 1000);
    CHECK_EQ(control::ramp_step(29500, 30000, 1000, 2000), 30000);
    CHECK_EQ(control::ramp_step(30000, 10000, 1000, 2000), 28000);     // slowing down: decel
    CHECK_EQ(control::ramp_step(1000, -30000, 1000, 2000), -1000);     // reversing: through zero at decel
    CHECK_EQ(control::ramp_step(0, -30000, 1000, 2000), -1000);        // from 0: accel
    CHECK_EQ(control::ramp_step(-10000, -30000, 1000, 2000), -11000);  // speeding up backwards: accel
    CHECK_EQ(control::ramp_step(-10000, 0, 1000, 2000), -8000);
    CHECK_EQ(control::ramp_step(-500, 0, 1000, 2000), 0);
    CHECK_EQ(control::ramp_step(0, 1, 1, 1), 1);                        // 1 mm/s^2: 0.01 mm/s per tick
    CHECK_EQ(control::ramp_step(-3276800, 3276700, 65535, 65535), -3276800 + 65535);
}

static void test_pid_math() {
    control::Gains g = {1.0f, 10.0f, 0.0f, 0.5f, 0.0f};
    float integral = 0;
    bool sat = false;

    CONTEXT("pid: P + FF, then integral");
    int16_t u = control::pid_step(g, 100.0f, 60, 60, 1000, integral, sat);
    CHECK_EQ(u, 50 + 40);                      // kf*r + kp*e (integral was 0)
    CHECK(fabsf(integral - 10.0f * 40 * 0.01f) < 1e-4f);
    CHECK(!sat);

    CONTEXT("pid: static friction fed forward with the setpoint's sign, none at a zero setpoint");
    control::Gains gs = {0.0f, 0.0f, 0.0f, 1.0f, 80.0f};
    integral = 0;
    CHECK_EQ(control::pid_step(gs, 10.0f, 0, 0, 1000, integral, sat), 90);
    CHECK_EQ(control::pid_step(gs, -0.01f, 0, 0, 1000, integral, sat), -80);  // reversing: at once
    CHECK_EQ(control::pid_step(gs, 0.0f, 0, 0, 1000, integral, sat), 0);
    CHECK_EQ(control::pid_step(gs, 950.0f, 0, 0, 1000, integral, sat), 1000);  // part of the clamped sum
    CHECK(sat);

    CONTEXT("pid: derivative on measurement (no kick on a setpoint step)");
    control::Gains gd = {0.0f, 0.0f, 2.0f, 0.0f, 0.0f};
    integral = 0;
    CHECK_EQ(control::pid_step(gd, 500, 100, 100, 1000, integral, sat), 0);      // r jumped, m did not
    CHECK_EQ(control::pid_step(gd, 500, 110, 100, 1000, integral, sat), -1000);  // -2000, clamped
    CHECK_EQ(control::pid_step(gd, 500, 101, 100, 1000, integral, sat), -200);   // -kd * 1 / 0.01

    CONTEXT("pid: output limits");
    control::Gains big = {50.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    integral = 0;
    CHECK_EQ(control::pid_step(big, 1000, 0, 0, 400, integral, sat), 400);
    CHECK(sat);
    CHECK_EQ(control::pid_step(big, -1000, 0, 0, 400, integral, sat), -400);
    CHECK(sat);

    CONTEXT("pid: conditional integration (anti-windup)");
    control::Gains gi = {1.0f, 50.0f, 0.0f, 0.0f, 0.0f};
    integral = 0;
    for (int i = 0; i < 1000; ++i) {
        control::pid_step(gi, 800, 0, 0, 500, integral, sat);  // hopelessly saturated
    }
    CHECK(sat);
    CHECK(integral == 0.0f);  // e > 0 pushes further into saturation: never integrated
    // Saturated high while the error is negative: integrating pulls u back, so it is allowed.
    control::Gains gb = {1.0f, 50.0f, 0.0f, 10.0f, 0.0f};
    integral = 480;
    control::pid_step(gb, 100, 150, 150, 500, integral, sat);  // u_unsat = 1000 - 50 + 480
    CHECK(sat);
    CHECK(fabsf(integral - (480.0f - 25.0f)) < 1e-3f);
    // Saturated low while the error is negative too: no integration.
    integral = -100;
    control::pid_step(gi, 100, 1200, 1200, 500, integral, sat);  // u_unsat = -1100 - 100
    CHECK(sat);
    CHECK(integral == -100.0f);
    // A naive integrator would have wound up to the clamp; the integral is also clamped.
    control::Gains wind = {0.0f, 1000.0f, 0.0f, 0.0f, 0.0f};
    integral = 0;
    for (int i = 0; i < 100; ++i) {
        control::pid_step(wind, 10, 0, 0, 300, integral, sat);
    }
    CHECK(integral <= 300.0f);
    CHECK(integral > 290.0f);
}

static void test_measure_math() {
    CONTEXT("measured speed");
    proto::SetConfig c = TB6612.default_config();  // 64 mm wheels, 1560 counts/rev
    const float k = control::mm_s_per_count(c);
    // 78 counts in 10 ms = 78 * pi * 64 / 1560 / 0.01 mm/s = 1005.3
    CHECK_EQ(control::measure_speed(78, k, 1), 1005);
    CHECK_EQ(control::measure_speed(-78, k, 1), -1005);
    CHECK_EQ(control::measure_speed(156, k, 2), 1005);  // a late tick spanning two periods
    CHECK_EQ(control::measure_speed(0, k, 1), 0);
    CHECK_EQ(control::measure_speed(2000000000, k, 1), 32767);  // saturates, no UB
}

static void test_steering_math() {
    const proto::SetConfig c = PICAR.default_config();  // centre 9000, 6500..12500, step 1500
    struct Case {
        int16_t mrad;
        uint16_t cdeg;
        uint16_t pulse;
        int16_t back;
    };
    const Case cases[] = {
        {0, 9000, 1500, 0},        {100, 9000, 1500, 0},       {300, 10500, 1667, 262},
        {-300, 7500, 1333, -262},  {1571, 12000, 1833, 524},   {-1571, 6500, 1222, -436},
        {262, 10500, 1667, 262},   {-130, 9000, 1500, 0},      {-131, 7500, 1333, -262},  // -750.6 cdeg
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        CONTEXT("steering mrad=%d", cases[i].mrad);
        const uint16_t cdeg = control::steering_cdeg(cases[i].mrad, c);
        CHECK_EQ(cdeg, cases[i].cdeg);
        CHECK_EQ(control::servo_pulse_us(cdeg, c), cases[i].pulse);
        CHECK_EQ(control::steering_mrad(cdeg, c), cases[i].back);
    }
    CONTEXT("angle conversions equal double-precision round-half-away-from-zero everywhere");
    proto::SetConfig wide = c;
    wide.steering_center_cdeg = 9000;
    wide.steering_min_cdeg = 0;
    wide.steering_max_cdeg = 18000;
    wide.steering_step_cdeg = 0;
    int mismatches = 0;
    for (int mrad = -1571; mrad <= 1571; ++mrad) {
        const double exact = mrad * 18000.0 / (1000.0 * M_PI);
        long want = 9000 + (exact >= 0 ? static_cast<long>(exact + 0.5) : -static_cast<long>(-exact + 0.5));
        want = want < 0 ? 0 : (want > 18000 ? 18000 : want);  // +-1571 mrad is just past +-90 degrees
        mismatches += control::steering_cdeg(static_cast<int16_t>(mrad), wide) != want;
    }
    for (int cdeg = 0; cdeg <= 18000; ++cdeg) {
        for (int center = 0; center <= 18000; center += 18000) {
            wide.steering_center_cdeg = static_cast<uint16_t>(center);
            const double exact = (cdeg - center) * 1000.0 * M_PI / 18000.0;
            const long want = exact >= 0 ? static_cast<long>(exact + 0.5) : -static_cast<long>(-exact + 0.5);
            mismatches += control::steering_mrad(static_cast<uint16_t>(cdeg), wide) != want;
        }
    }
    CHECK_EQ(mismatches, 0);
    CONTEXT("steering, continuous (step 0)");
    proto::SetConfig cont = c;
    cont.steering_step_cdeg = 0;
    CHECK_EQ(control::steering_cdeg(100, cont), 9573);  // 100 * 18000 / (1000 pi) = 572.96
    CHECK_EQ(control::steering_cdeg(-100, cont), 8427);
    CHECK_EQ(control::steering_mrad(9573, cont), 100);
}

static void test_pulse_math() {
    CONTEXT("ESC pulses");
    proto::SetConfig c = PICAR.default_config();  // 1000 / 1500 / 2000
    CHECK_EQ(control::esc_pulse_us(0, c), 1500);
    CHECK_EQ(control::esc_pulse_us(600, c), 1800);
    CHECK_EQ(control::esc_pulse_us(-600, c), 1200);
    CHECK_EQ(control::esc_pulse_us(1000, c), 2000);
    CHECK_EQ(control::esc_pulse_us(-1000, c), 1000);
    CHECK_EQ(control::esc_pulse_us(1, c), 1501);    // 1500.5 rounds away from zero
    CHECK_EQ(control::esc_pulse_us(-1, c), 1499);   // 1499.5 rounds away from zero
    c.esc_min_us = 1100;                            // asymmetric: reverse span 400 us
    CHECK_EQ(control::esc_pulse_us(-500, c), 1300);
    CHECK_EQ(control::esc_pulse_us(500, c), 1750);
    CONTEXT("servo pulses");
    CHECK_EQ(control::servo_pulse_us(0, c), 500);
    CHECK_EQ(control::servo_pulse_us(18000, c), 2500);
    CHECK_EQ(control::servo_pulse_us(9000, c), 1500);
}

static void test_lights_math() {
    const proto::SetLights AUTO = {proto::LightsMode::AUTO, 0, 0, 0};
    using control::lights_for;
    const uint8_t LEFT = Lights::FRONT_LEFT | Lights::REAR_LEFT;
    const uint8_t RIGHT = Lights::FRONT_RIGHT | Lights::REAR_RIGHT;
    const uint8_t FRONT = Lights::FRONT_LEFT | Lights::FRONT_RIGHT;
    const uint8_t REAR = Lights::REAR_LEFT | Lights::REAR_RIGHT;
    const uint8_t ALL = LEFT | RIGHT;
    CONTEXT("lights");
    CHECK_EQ(lights_for(AUTO, SessionState::IDLE, 0, 0, 0, false, 0), FRONT);
    CHECK_EQ(lights_for(AUTO, SessionState::DISARMED, 0, 0, 0, false, 40), REAR);
    CHECK_EQ(lights_for(AUTO, SessionState::ARMED, 0, 0, 0, false, 0), 0);
    CHECK_EQ(lights_for(AUTO, SessionState::ARMED, 200, 200, 0, false, 0), 0);
    CHECK_EQ(lights_for(AUTO, SessionState::ARMED, 100, 200, 0, false, 0), LEFT);
    CHECK_EQ(lights_for(AUTO, SessionState::ARMED, 100, 200, 0, false, 40), 0);  // blink off phase
    CHECK_EQ(lights_for(AUTO, SessionState::ARMED, 200, 100, 0, false, 0), RIGHT);
    CHECK_EQ(lights_for(AUTO, SessionState::ARMED, 0, 150, 0, false, 0), LEFT);   // pivot on the left wheel
    CHECK_EQ(lights_for(AUTO, SessionState::ARMED, -150, 150, 0, false, 0), ALL);  // in place: hazard
    CHECK_EQ(lights_for(AUTO, SessionState::ARMED, 200, 210, 0, false, 0), 0);    // within 1/8: straight
    CHECK_EQ(lights_for(AUTO, SessionState::ARMED, -200, -100, 0, false, 0), LEFT);
    CHECK_EQ(lights_for(AUTO, SessionState::ARMED, 300, 0, 1500, true, 0), LEFT);
    CHECK_EQ(lights_for(AUTO, SessionState::ARMED, 300, 0, -1500, true, 0), RIGHT);
    CHECK_EQ(lights_for(AUTO, SessionState::FAILSAFE, 0, 0, 0, false, 0), ALL);
    CHECK_EQ(lights_for(AUTO, SessionState::FAILSAFE, 0, 0, 0, false, 20), 0);  // 3 Hz
    CHECK_EQ(lights_for(AUTO, SessionState::FAILSAFE, 0, 0, 0, false, 33), ALL);
    // Duty: over one blink period, the turn signal is on for half of it.
    int on = 0;
    for (uint8_t b = 0; b < control::BLINK_PERIOD_TICKS; ++b) {
        on += lights_for(AUTO, SessionState::ARMED, 100, 200, 0, false, b) != 0;
    }
    CHECK_EQ(on, control::BLINK_PERIOD_TICKS / 2);
    // SET_LIGHTS outside AUTO: front left steady, rear left slow, rear right fast.
    const proto::SetLights manual = {proto::LightsMode::MANUAL, 1, 4, 8};
    CHECK_EQ(lights_for(manual, SessionState::ARMED, 100, 200, 0, false, 0), 13);  // both blinks on
    CHECK_EQ(lights_for(manual, SessionState::DISARMED, 0, 0, 0, false, 20), 5);  // fast off (16 of 33)
    CHECK_EQ(lights_for(manual, SessionState::IDLE, 0, 0, 0, false, 33), 9);     // slow off, fast on again
    CHECK_EQ(lights_for(manual, SessionState::ARMED, -150, 150, 0, false, 50), 1);  // only the steady one
    CHECK_EQ(lights_for(manual, SessionState::FAILSAFE, 0, 0, 0, false, 0), ALL);  // FAILSAFE in every mode
    const proto::SetLights off = {proto::LightsMode::OFF, 1, 4, 8};
    CHECK_EQ(lights_for(off, SessionState::DISARMED, 0, 0, 0, false, 0), 0);  // masks light nothing outside MANUAL
    CHECK_EQ(lights_for(off, SessionState::FAILSAFE, 0, 0, 0, false, 20), 0);
}

static void test_config_validation() {
    CONTEXT("config field indices match check_ranges");
    proto::SetConfig c = TB6612.default_config();
    proto::SetConfig bad = c;
    bad.steering_center_cdeg = 18001;
    CHECK_EQ(proto::check_ranges(bad), config::FIELD_STEERING_CENTER);
    bad = c;
    bad.servo_min_us = 1;
    CHECK_EQ(proto::check_ranges(bad), config::FIELD_SERVO_MIN);
    bad = c;
    bad.esc_min_us = 1;
    CHECK_EQ(proto::check_ranges(bad), config::FIELD_ESC_MIN);
    bad = c;
    bad.esc_neutral_us = 1;
    CHECK_EQ(proto::check_ranges(bad), config::FIELD_ESC_NEUTRAL);

    NackReason why;
    uint8_t detail;
    CONTEXT("config validation");
    for (int i = 0; i < sim_profiles::count(); ++i) {
        CHECK(config::validate(sim_profiles::at(i)->robot->default_config(), why, detail));
    }
    bad = c;
    bad.watchdog_ms = 10;
    CHECK(!config::validate(bad, why, detail) && why == NackReason::OUT_OF_RANGE && detail == 0);
    bad = c;
    bad.feedback_hz = 0;
    CHECK(!config::validate(bad, why, detail) && why == NackReason::OUT_OF_RANGE && detail == 20);
    bad = c;
    bad.steering_min_cdeg = 9500;  // > centre
    CHECK(!config::validate(bad, why, detail) && why == NackReason::INVALID_CONFIG && detail == 10);
    bad = c;
    bad.steering_max_cdeg = 8000;  // < centre
    CHECK(!config::validate(bad, why, detail) && why == NackReason::INVALID_CONFIG && detail == 10);
    bad = c;
    bad.servo_max_us = bad.servo_min_us;
    CHECK(!config::validate(bad, why, detail) && why == NackReason::INVALID_CONFIG && detail == 14);
    bad = c;
    bad.esc_min_us = bad.esc_neutral_us;
    CHECK(!config::validate(bad, why, detail) && why == NackReason::INVALID_CONFIG && detail == 16);
    bad = c;
    bad.esc_max_us = bad.esc_neutral_us;
    CHECK(!config::validate(bad, why, detail) && why == NackReason::INVALID_CONFIG && detail == 17);
}

// -------------------------------------------------------------------------------------------------
// Boot and handshake

static void test_boot_announcement() {
    CONTEXT("boot: IDENTITY(BOOT) then LOG(WARN) on a blank EEPROM");
    Sim s(TB6612, 7);
    Host h(s);
    h.pump();
    CHECK(h.frames.size() >= 2);
    CHECK_EQ(h.frames[0].id, proto::Identity::ID);
    CHECK_EQ(h.frames[0].seq, 0);
    proto::Identity id;
    CHECK(proto::unpack(h.frames[0].payload.data(), static_cast<uint8_t>(h.frames[0].payload.size()), id));
    CHECK(id.reason == proto::IdentityReason::BOOT);
    CHECK_EQ(id.protocol_version, proto::PROTOCOL_VERSION);
    CHECK_EQ(id.spec_hash, proto::SPEC_HASH);
    CHECK_EQ(id.firmware_version[0], ROVERLINK_FIRMWARE_VERSION_MAJOR);
    CHECK_EQ(id.firmware_version[1], ROVERLINK_FIRMWARE_VERSION_MINOR);
    CHECK_EQ(id.firmware_version[2], ROVERLINK_FIRMWARE_VERSION_PATCH);
    CHECK(id.board == proto::Board::MEGA2560);
    CHECK_EQ(id.capabilities, TB6612.capabilities);
    CHECK_EQ(id.boot_id, s.fw->boot_id());
    CHECK(id.boot_id != 0);
    CHECK_EQ(id.hello_seq, 0);
    CHECK_EQ(id.watchdog_ms, 250);
    CHECK(id.feedback_mode == FeedbackMode::STREAM);
    CHECK_EQ(id.feedback_hz, 50);
    CHECK(std::string(id.robot_name, id.robot_name_len) == "DiffDriveTB6612");
    CHECK_EQ(h.frames[1].id, proto::Log::ID);
    proto::Log log;
    CHECK(h.last(log));
    CHECK(log.level == proto::LogLevel::WARN);
    CHECK(std::string(log.text, log.text_len).find("defaults") != std::string::npos);
    CHECK(s.fw->state() == SessionState::IDLE);
    CHECK(s.fw->status() & proto::Status::CONFIG_DEFAULTS);

    CONTEXT("boot: motors safe, ESC neutral and steering centred from the start");
    CHECK(s.board.motor(0).mode == MotorMode::BRAKE && s.board.motor(1).mode == MotorMode::BRAKE);
    Sim car(PICAR, 7);
    CHECK_EQ(car.board.esc_us(), 1500);
    CHECK_EQ(car.board.steering_us(), 1500);
    CHECK_EQ(car.board.motor(0).calls, 0u);  // an ESC robot never drives a DC channel

    CONTEXT("boot: IDLE streams FEEDBACK at the config rate before any HELLO");
    h.clear();
    h.run(1000000);
    CHECK_EQ(h.count<proto::Feedback>(), 50u);
    proto::Feedback fb;
    CHECK(h.last(fb));
    CHECK_EQ(fb.boot_id, s.fw->boot_id());
    CHECK_EQ(fb.status, proto::Status::CONFIG_DEFAULTS);
    CHECK_EQ(h.mcu_seq_gaps(), 0u);
}

static void test_handshake_bytes() {
    CONTEXT("handshake: exact IDENTITY(HELLO_ACCEPTED) bytes");
    Sim s(TB6612, 11);
    Host h(s);
    s.advance_us(45500);  // between ticks: the reply is the only frame of this poll
    uint8_t drain[4096];
    while (s.read(drain, sizeof drain) > 0) {
    }
    const uint8_t mcu_seq = s.fw->link().next_tx_seq();
    const uint8_t hseq = h.send(hello(FeedbackMode::STREAM, 20, 300));
    s.advance_us(0);
    uint8_t got[256];
    const size_t n = s.read(got, sizeof got);

    proto::Identity want = proto::Identity();
    want.protocol_version = proto::PROTOCOL_VERSION;
    want.spec_hash = proto::SPEC_HASH;
    want.firmware_version[0] = ROVERLINK_FIRMWARE_VERSION_MAJOR;
    want.firmware_version[1] = ROVERLINK_FIRMWARE_VERSION_MINOR;
    want.firmware_version[2] = ROVERLINK_FIRMWARE_VERSION_PATCH;
    want.board = proto::Board::MEGA2560;
    want.capabilities = TB6612.capabilities;
    want.boot_id = s.fw->boot_id();
    want.uptime_ms = 45;
    want.reason = proto::IdentityReason::HELLO_ACCEPTED;
    want.hello_seq = hseq;
    want.watchdog_ms = 300;
    want.feedback_mode = FeedbackMode::STREAM;
    want.feedback_hz = 20;
    const char* name = "DiffDriveTB6612";
    want.robot_name_len = static_cast<uint8_t>(strlen(name));
    memcpy(want.robot_name, name, want.robot_name_len);
    uint8_t expect[proto::MAX_FRAME];
    const size_t m = encode_message(want, mcu_seq, expect, sizeof expect);
    CHECK_EQ(n, m);
    CHECK(n == m && memcmp(got, expect, n) == 0);
    CHECK(s.fw->state() == SessionState::DISARMED);
    CHECK_EQ(s.fw->watchdog_ms(), 300);
    CHECK_EQ(s.fw->feedback_hz(), 20);

    CONTEXT("handshake: grants are clamped");
    h.send(hello(FeedbackMode::STREAM, 255, 5));
    h.run();
    proto::Identity id;
    CHECK(h.last(id) && id.watchdog_ms == proto::WATCHDOG_MIN_MS && id.feedback_hz == proto::FEEDBACK_HZ_MAX);
    h.send(hello(FeedbackMode::STREAM, 0, 60000));
    h.run();
    CHECK(h.last(id) && id.watchdog_ms == proto::WATCHDOG_MAX_MS && id.feedback_hz == 50);
    h.send(hello(FeedbackMode::LOCKSTEP, 0, 0));
    h.run();
    CHECK(h.last(id) && id.watchdog_ms == 250 && id.feedback_mode == FeedbackMode::LOCKSTEP);
    CHECK(s.fw->status() & proto::Status::LOCKSTEP);
}

static void test_hello_rejected() {
    CONTEXT("handshake: spec hash mismatch refused, never arms");
    Sim s(TB6612, 12);
    Host h(s);
    h.run();
    proto::Hello bad = hello();
    bad.spec_hash ^= 0x00010000u;
    const uint8_t seq = h.send(bad);
    h.run();
    proto::Identity id;
    CHECK(h.last(id));
    CHECK(id.reason == proto::IdentityReason::HELLO_REJECTED);
    CHECK_EQ(id.hello_seq, seq);
    CHECK_EQ(id.spec_hash, proto::SPEC_HASH);  // the firmware's own, so the host can name both
    CHECK_EQ(id.protocol_version, proto::PROTOCOL_VERSION);
    CHECK(s.fw->state() == SessionState::IDLE);
    const uint8_t aseq = h.send(arm_msg(s.fw->boot_id()));
    h.run();
    CHECK(nacked(h, proto::Arm::ID, aseq, NackReason::NO_SESSION));
    CHECK(s.fw->state() == SessionState::IDLE);
    const uint8_t sseq = h.send(wheels(100, 100));
    h.run(100000);
    CHECK(s.fw->state() == SessionState::IDLE);
    CHECK_EQ(s.board.motor(0).effort, 0);
    bool refused = false;
    std::vector<proto::Nack> nacks = h.all<proto::Nack>();
    for (size_t i = 0; i < nacks.size(); ++i) {
        refused = refused || (nacks[i].req_seq == sseq && nacks[i].reason == NackReason::NO_SESSION);
    }
    CHECK(refused);

    CONTEXT("handshake: protocol version mismatch refused");
    proto::Hello old = hello();
    old.protocol_version = static_cast<uint8_t>(proto::PROTOCOL_VERSION + 1);
    h.send(old);
    h.run();
    CHECK(h.last(id) && id.reason == proto::IdentityReason::HELLO_REJECTED);

    CONTEXT("handshake: an incompatible HELLO closes an open session");
    open_and_arm(s, h);
    CHECK(s.fw->state() == SessionState::ARMED);
    h.send(bad);
    h.run();
    CHECK(s.fw->state() == SessionState::IDLE);
    CHECK(!(s.fw->status() & proto::Status::SESSION));
    CHECK(s.board.motor(0).mode == MotorMode::BRAKE);
}

static void test_arm_and_setpoint_refusals() {
    Sim s(TB6612, 13);
    Host h(s);
    h.run();

    CONTEXT("IDLE: setpoints and reliable requests need a session");
    uint8_t seq = h.send(wheels(10, 10));
    h.run();
    CHECK(nacked(h, proto::SetWheelSpeeds::ID, seq, NackReason::NO_SESSION));
    seq = h.send(proto::GetConfig());
    h.run();
    CHECK(nacked(h, proto::GetConfig::ID, seq, NackReason::NO_SESSION));
    seq = h.send(proto::SaveConfig());
    h.run();
    CHECK(nacked(h, proto::SaveConfig::ID, seq, NackReason::NO_SESSION));
    seq = h.send(proto::ResetOdometry());
    h.run();
    CHECK(nacked(h, proto::ResetOdometry::ID, seq, NackReason::NO_SESSION));
    seq = h.send(proto::GetLinkStats());
    h.run();
    CHECK(nacked(h, proto::GetLinkStats::ID, seq, NackReason::NO_SESSION));
    proto::GetPid gp = {0};
    seq = h.send(gp);
    h.run();
    CHECK(nacked(h, proto::GetPid::ID, seq, NackReason::NO_SESSION));
    proto::SetPid sp = TB6612.default_pid();
    seq = h.send(sp);
    h.run();
    CHECK(nacked(h, proto::SetPid::ID, seq, NackReason::NO_SESSION));
    seq = h.send(config_of(s));
    h.run();
    CHECK(nacked(h, proto::SetConfig::ID, seq, NackReason::NO_SESSION));
    seq = h.send(proto::Disarm());
    h.run();
    CHECK(acked(h, proto::Disarm::ID, seq));  // the table: IDLE DISARM -> ack

    CONTEXT("DISARMED: setpoint refused with NOT_ARMED, never applied");
    open_session(h);
    seq = h.send(wheels(200, 200));
    h.run(50000);
    CHECK(s.fw->state() == SessionState::DISARMED);
    bool refused = false;
    std::vector<proto::Nack> nacks = h.all<proto::Nack>();
    for (size_t i = 0; i < nacks.size(); ++i) {
        refused = refused || (nacks[i].req_seq == seq && nacks[i].reason == NackReason::NOT_ARMED);
    }
    CHECK(refused);
    CHECK_EQ(s.fw->target(0), 0);
    CHECK(s.board.motor(0).mode != MotorMode::DRIVE);

    CONTEXT("unsupported setpoint kind");
    seq = h.send(ackermann(100, 0));
    h.run();
    CHECK(nacked(h, proto::SetAckermann::ID, seq, NackReason::UNSUPPORTED));

    CONTEXT("ARM with another boot's id is refused");
    seq = h.send(arm_msg(s.fw->boot_id() ^ 1u));
    h.run();
    CHECK(nacked(h, proto::Arm::ID, seq, NackReason::BOOT_ID_MISMATCH));
    CHECK(s.fw->state() == SessionState::DISARMED);
    seq = h.send(arm_msg(s.fw->boot_id()));
    h.run();
    CHECK(acked(h, proto::Arm::ID, seq));
    CHECK(s.fw->state() == SessionState::ARMED);

    CONTEXT("ARMED: over-speed refused (field index), not applied");
    seq = h.send(wheels(100, 100));
    h.run(10000);
    CHECK_EQ(s.fw->target(0), 100);
    seq = h.send(wheels(601, 0));
    h.run(10000);
    CHECK(nacked(h, proto::SetWheelSpeeds::ID, seq, NackReason::OUT_OF_RANGE, 0));
    seq = h.send(wheels(0, -601));
    h.run(10000);
    CHECK(nacked(h, proto::SetWheelSpeeds::ID, seq, NackReason::OUT_OF_RANGE, 1));
    CHECK_EQ(s.fw->target(0), 100);
    CHECK_EQ(s.fw->target(1), 100);
    seq = h.send(wheels(-600, 600));
    h.run(10000);
    CHECK_EQ(s.fw->target(0), -600);
    CHECK_EQ(s.fw->ack_seq(), seq);

    CONTEXT("ARM while ARMED: ACK; DISARM: ACK and safe");
    seq = h.send(arm_msg(s.fw->boot_id()));
    h.run();
    CHECK(acked(h, proto::Arm::ID, seq) && s.fw->state() == SessionState::ARMED);
    seq = h.send(proto::Disarm());
    h.run();
    CHECK(acked(h, proto::Disarm::ID, seq) && s.fw->state() == SessionState::DISARMED);
    CHECK_EQ(s.fw->target(0), 0);
    CHECK(s.board.motor(0).mode == MotorMode::BRAKE && s.board.motor(0).effort == 0);
}

static void test_ackermann_refusals() {
    Sim s(PICAR, 14);
    Host h(s);
    open_and_arm(s, h);
    CONTEXT("picar: wheel speeds unsupported, steering range checked");
    uint8_t seq = h.send(wheels(100, 100));
    h.run();
    CHECK(nacked(h, proto::SetWheelSpeeds::ID, seq, NackReason::UNSUPPORTED));
    seq = h.send(ackermann(100, 1572));
    h.run();
    CHECK(nacked(h, proto::SetAckermann::ID, seq, NackReason::OUT_OF_RANGE, 1));
    seq = h.send(ackermann(2001, 0));
    h.run();
    CHECK(nacked(h, proto::SetAckermann::ID, seq, NackReason::OUT_OF_RANGE, 0));
    seq = h.send(ackermann(-2001, 2000));  // both bad: the first field's index
    h.run();
    CHECK(nacked(h, proto::SetAckermann::ID, seq, NackReason::OUT_OF_RANGE, 0));
}

static void test_ping() {
    CONTEXT("PING answered with PONG in every state");
    Sim s(TB6612, 15);
    Host h(s);
    s.advance_us(123456);
    proto::Ping p = {0xDEADBEEFu};
    h.send(p);
    h.run();
    proto::Pong pong;
    CHECK(h.last(pong));
    CHECK_EQ(pong.host_time_us, 0xDEADBEEFu);
    CHECK_EQ(pong.mcu_time_us, 123456u);
    CHECK_EQ(last_id(h), proto::Pong::ID);
}

static void test_one_frame_per_poll() {
    CONTEXT("poll(): one frame per pass, so a host that keeps sending cannot hold the loop");
    Sim s(TB6612, 16);
    Host h(s);
    h.run(1000);
    h.frames.clear();
    for (uint32_t i = 0; i < 5; ++i) {
        proto::Ping p = {i};
        h.send(p);
    }
    s.fw->poll();  // one pass of the sketch's loop()
    h.pump();
    CHECK_EQ(h.frames.size(), 1u);
    proto::Pong pong;
    CHECK(h.last(pong) && pong.host_time_us == 0u);
    CHECK(s.port.available() > 0);  // the other four wait in the receive buffer, unread
    h.run();                        // the next passes, at the same instant
    CHECK_EQ(h.frames.size(), 5u);
    CHECK(h.last(pong) && pong.host_time_us == 4u);
    CHECK_EQ(s.port.available(), 0);
}

static void test_reset_new_boot_id() {
    CONTEXT("power cycle: new boot_id, new IDENTITY, old ARM refused");
    Sim s(TB6612, 16);
    Host h(s);
    open_and_arm(s, h);
    const uint32_t old_id = s.fw->boot_id();
    std::set<uint32_t> ids;
    ids.insert(old_id);
    for (int i = 0; i < 20; ++i) {
        s.power_cycle();
        h.resync_mcu_seq();
        h.clear();
        h.pump();
        CHECK(!h.frames.empty() && h.frames[0].id == proto::Identity::ID);
        proto::Identity id;
        CHECK(h.all<proto::Identity>().size() == 1);
        id = h.all<proto::Identity>()[0];
        CHECK(id.reason == proto::IdentityReason::BOOT);
        CHECK(id.boot_id != 0);
        CHECK_EQ(id.boot_id, s.fw->boot_id());
        ids.insert(id.boot_id);
        CHECK(s.fw->state() == SessionState::IDLE);
    }
    CHECK_EQ(ids.size(), 21u);
    // Same noise, but the EEPROM boot counter differs: still a new id.
    Sim a(TB6612, 99);
    Sim b(TB6612, 99);
    CHECK_EQ(a.fw->boot_id(), b.fw->boot_id());  // deterministic simulation
    b.power_cycle();
    CHECK(b.fw->boot_id() != a.fw->boot_id());

    open_session(h);
    const uint8_t seq = h.send(arm_msg(old_id));
    h.run();
    CHECK(nacked(h, proto::Arm::ID, seq, NackReason::BOOT_ID_MISMATCH));
    CHECK(s.fw->state() == SessionState::DISARMED);
}

// -------------------------------------------------------------------------------------------------
// Reliable requests

static void test_duplicates() {
    Sim s(TB6612, 17);
    Host h(s);
    open_session(h);

    CONTEXT("duplicate RESET_ODOMETRY answered, applied once");
    s.board.set_encoder(0, 500);
    h.run(20000);
    const uint8_t seq = h.send(proto::ResetOdometry());
    h.run();
    CHECK(acked(h, proto::ResetOdometry::ID, seq));
    CHECK_EQ(s.board.encoder(0), 0);
    CHECK_EQ(s.board.zero_encoder_calls(), 1u);
    s.board.set_encoder(0, 50);
    h.send_seq(proto::ResetOdometry(), seq);
    h.run();
    CHECK(acked(h, proto::ResetOdometry::ID, seq));
    CHECK_EQ(s.board.encoder(0), 50);
    CHECK_EQ(s.board.zero_encoder_calls(), 1u);
    CHECK_EQ(s.fw->duplicates(), 1u);

    CONTEXT("duplicate SET_CONFIG (even with other contents) not applied");
    proto::SetConfig c1 = config_of(s);
    c1.accel_limit_mm_s2 = 1234;
    const uint8_t cseq = h.send(c1);
    h.run();
    CHECK(acked(h, proto::SetConfig::ID, cseq));
    proto::SetConfig c2 = c1;
    c2.accel_limit_mm_s2 = 4321;
    h.send_seq(c2, cseq);
    h.run();
    CHECK(acked(h, proto::SetConfig::ID, cseq));
    CHECK_EQ(s.fw->config().accel_limit_mm_s2, 1234);
    CHECK_EQ(s.fw->duplicates(), 2u);

    CONTEXT("duplicate NACKed ARM: the same NACK again, never applied");
    const uint8_t aseq = h.send(arm_msg(s.fw->boot_id() + 1));
    h.run();
    CHECK(nacked(h, proto::Arm::ID, aseq, NackReason::BOOT_ID_MISMATCH));
    h.send_seq(arm_msg(s.fw->boot_id()), aseq);  // a "retry" carrying another payload
    h.run();
    CHECK(nacked(h, proto::Arm::ID, aseq, NackReason::BOOT_ID_MISMATCH));
    CHECK(s.fw->state() == SessionState::DISARMED);
    CHECK_EQ(s.fw->duplicates(), 3u);

    CONTEXT("duplicate GET_CONFIG: a fresh reply with the current values");
    const uint8_t gseq = h.send(proto::GetConfig());
    h.run();
    proto::Config cfg;
    CHECK(h.last(cfg) && cfg.req_seq == gseq && cfg.accel_limit_mm_s2 == 1234);
    const uint8_t c3seq = h.send(c2);
    h.run();
    CHECK(acked(h, proto::SetConfig::ID, c3seq));
    h.send_seq(proto::GetConfig(), gseq);  // not a duplicate: the last reliable was SET_CONFIG
    h.run();
    CHECK(h.last(cfg) && cfg.req_seq == gseq && cfg.accel_limit_mm_s2 == 4321);
    h.send_seq(proto::GetConfig(), gseq);
    h.run();
    CHECK(h.last(cfg) && cfg.req_seq == gseq && cfg.accel_limit_mm_s2 == 4321);
    CHECK_EQ(s.fw->duplicates(), 4u);

    CONTEXT("an accepted HELLO clears the duplicate memory");
    const uint8_t rseq = h.send(proto::ResetOdometry());
    h.run();
    CHECK_EQ(s.board.zero_encoder_calls(), 2u);
    open_session(h);
    h.send_seq(proto::ResetOdometry(), rseq);
    h.run();
    CHECK(acked(h, proto::ResetOdometry::ID, rseq));
    CHECK_EQ(s.board.zero_encoder_calls(), 3u);
    CHECK_EQ(s.fw->duplicates(), 4u);
}

static void test_pid_requests() {
    Sim s(TB6612, 18);
    Host h(s);
    open_session(h);
    CONTEXT("SET_PID / GET_PID");
    proto::SetPid p = {1, 2.5f, 3.5f, 0.25f, 1.25f, 40.0f};
    uint8_t seq = h.send(p);
    h.run();
    CHECK(acked(h, proto::SetPid::ID, seq));
    proto::GetPid g = {1};
    seq = h.send(g);
    h.run();
    proto::Pid pid;
    CHECK(h.last(pid));
    CHECK(pid.req_seq == seq && pid.wheel == 1 && pid.kp == 2.5f && pid.ki == 3.5f && pid.kd == 0.25f &&
          pid.kf == 1.25f && pid.ks == 40.0f);
    g.wheel = 0;
    seq = h.send(g);
    h.run();
    CHECK(h.last(pid) && pid.wheel == 0 && pid.kp == TB6612.default_pid().kp);
    g.wheel = 2;
    seq = h.send(g);
    h.run();
    CHECK(nacked(h, proto::GetPid::ID, seq, NackReason::OUT_OF_RANGE, 0));

    p.wheel = 7;
    seq = h.send(p);
    h.run();
    CHECK(nacked(h, proto::SetPid::ID, seq, NackReason::OUT_OF_RANGE, 0));
    p.wheel = proto::PID_ALL_WHEELS;
    p.kp = NAN;
    seq = h.send(p);
    h.run();
    CHECK(nacked(h, proto::SetPid::ID, seq, NackReason::OUT_OF_RANGE, 1));
    p.kp = 1;
    p.kd = -1;
    seq = h.send(p);
    h.run();
    CHECK(nacked(h, proto::SetPid::ID, seq, NackReason::OUT_OF_RANGE, 3));
    p.kd = 0;
    p.kf = INFINITY;
    seq = h.send(p);
    h.run();
    CHECK(nacked(h, proto::SetPid::ID, seq, NackReason::OUT_OF_RANGE, 4));
    p.kf = 1;
    p.ks = 1000.5f;
    seq = h.send(p);
    h.run();
    CHECK(nacked(h, proto::SetPid::ID, seq, NackReason::OUT_OF_RANGE, 5));
    p.ks = 0;
    CHECK(s.fw->gains(0).kp == TB6612.default_pid().kp);  // refused: nothing changed
    p.kf = 2;
    seq = h.send(p);
    h.run();
    CHECK(acked(h, proto::SetPid::ID, seq));
    CHECK(s.fw->gains(0).kf == 2.0f && s.fw->gains(1).kf == 2.0f && s.fw->gains(1).kp == 1.0f);
}

static void test_config_requests() {
    Sim s(TB6612, 19);
    Host h(s);
    open_session(h);
    CONTEXT("GET_CONFIG mirrors the config");
    uint8_t seq = h.send(proto::GetConfig());
    h.run();
    proto::Config cfg;
    CHECK(h.last(cfg));
    const proto::SetConfig d = TB6612.default_config();
    CHECK(cfg.req_seq == seq && cfg.watchdog_ms == d.watchdog_ms && cfg.safe_state == d.safe_state &&
          cfg.accel_limit_mm_s2 == d.accel_limit_mm_s2 && cfg.decel_limit_mm_s2 == d.decel_limit_mm_s2 &&
          cfg.max_wheel_speed_mm_s == d.max_wheel_speed_mm_s && cfg.max_effort_permille == d.max_effort_permille &&
          cfg.encoder_cpr == d.encoder_cpr && cfg.encoder_invert == d.encoder_invert &&
          cfg.motor_invert == d.motor_invert && cfg.wheel_diameter_um == d.wheel_diameter_um &&
          cfg.steering_center_cdeg == d.steering_center_cdeg && cfg.steering_min_cdeg == d.steering_min_cdeg &&
          cfg.steering_max_cdeg == d.steering_max_cdeg && cfg.steering_step_cdeg == d.steering_step_cdeg &&
          cfg.servo_min_us == d.servo_min_us && cfg.servo_max_us == d.servo_max_us &&
          cfg.esc_min_us == d.esc_min_us && cfg.esc_neutral_us == d.esc_neutral_us &&
          cfg.esc_max_us == d.esc_max_us && cfg.esc_arm_ms == d.esc_arm_ms && cfg.feedback_hz == d.feedback_hz);

    CONTEXT("SET_CONFIG refused: OUT_OF_RANGE / INVALID_CONFIG with the field index; nothing changes");
    proto::SetConfig bad = d;
    bad.max_wheel_speed_mm_s = 0;
    seq = h.send(bad);
    h.run();
    CHECK(nacked(h, proto::SetConfig::ID, seq, NackReason::OUT_OF_RANGE, 4));
    bad = d;
    bad.esc_neutral_us = 2000;
    bad.decel_limit_mm_s2 = 77;
    seq = h.send(bad);
    h.run();
    CHECK(nacked(h, proto::SetConfig::ID, seq, NackReason::INVALID_CONFIG, 17));
    CHECK_EQ(s.fw->config().decel_limit_mm_s2, d.decel_limit_mm_s2);

    CONTEXT("SET_CONFIG accepted; the session's grants stay until the next HELLO");
    proto::SetConfig good = d;
    good.watchdog_ms = 1000;
    good.feedback_hz = 10;
    good.decel_limit_mm_s2 = 77;
    seq = h.send(good);
    h.run();
    CHECK(acked(h, proto::SetConfig::ID, seq));
    CHECK_EQ(s.fw->config().decel_limit_mm_s2, 77);
    CHECK_EQ(s.fw->watchdog_ms(), 250);
    CHECK_EQ(s.fw->feedback_hz(), 50);
    open_session(h);
    CHECK_EQ(s.fw->watchdog_ms(), 1000);
    CHECK_EQ(s.fw->feedback_hz(), 10);
}

// -------------------------------------------------------------------------------------------------
// Watchdog and failsafe

static void test_watchdog_timing() {
    const uint32_t phases_us[] = {0, 100, 1000, 3300, 5000, 7700, 9900, 10000, 12345};
    for (size_t i = 0; i < sizeof phases_us / sizeof phases_us[0]; ++i) {
        for (uint16_t wd = 50; wd <= 250; wd += 200) {
            CONTEXT("watchdog %u ms, ARM at phase %u us", wd, phases_us[i]);
            Sim s(TB6612, 20 + static_cast<uint32_t>(i));
            s.poll_interval_us = 100;
            Host h(s);
            s.advance_us(30000 + phases_us[i]);
            open_session(h, FeedbackMode::STREAM, 0, wd);
            h.send(arm_msg(s.fw->boot_id()));
            h.run();
            CHECK(s.fw->state() == SessionState::ARMED);
            const uint64_t last_frame = s.time_us();
            const uint64_t expiry = last_frame + static_cast<uint64_t>(wd) * 1000u;
            const uint64_t first_tick = (expiry + 9999) / 10000 * 10000;  // ticks on the 10 ms grid
            s.advance_us(first_tick - 100 - s.time_us());
            CHECK(s.fw->state() == SessionState::ARMED);
            s.advance_us(100);
            CHECK(s.fw->state() == SessionState::FAILSAFE);
            CHECK(s.time_us() - expiry < 10000);  // within one control tick of expiry
            CHECK(s.fw->failsafe_reason() == FailsafeReason::COMM_TIMEOUT);
            CHECK(s.board.motor(0).mode == MotorMode::BRAKE && s.board.motor(1).mode == MotorMode::BRAKE);
        }
    }
}

static void test_failsafe_latched() {
    Sim s(TB6612, 30);
    Host h(s);
    open_and_arm(s, h);
    const proto::SetWheelSpeeds go = wheels(200, 200);
    h.send(go);
    h.run(100000);
    CHECK(s.board.motor(0).mode == MotorMode::DRIVE);
    h.run(300000);  // silence: the watchdog expires
    CONTEXT("failsafe latched with its reason");
    CHECK(s.fw->state() == SessionState::FAILSAFE);
    CHECK(s.fw->failsafe_reason() == FailsafeReason::COMM_TIMEOUT);
    proto::Feedback fb;
    CHECK(h.last(fb));
    CHECK(fb.status & proto::Status::FAILSAFE);
    CHECK(!(fb.status & proto::Status::ARMED));
    CHECK(fb.failsafe_reason == FailsafeReason::COMM_TIMEOUT);
    CHECK_EQ(fb.effort_permille[0], 0);

    CONTEXT("frames do not clear a failsafe; setpoints are refused with the reason");
    proto::Ping ping = {1};
    h.send(ping);
    h.send(proto::GetConfig());
    const uint8_t seq = h.send(go);
    h.run(50000);
    CHECK(s.fw->state() == SessionState::FAILSAFE);
    bool refused = false;
    std::vector<proto::Nack> nacks = h.all<proto::Nack>();
    for (size_t i = 0; i < nacks.size(); ++i) {
        refused = refused || (nacks[i].req_seq == seq && nacks[i].reason == NackReason::FAILSAFE &&
                              nacks[i].detail == static_cast<uint8_t>(FailsafeReason::COMM_TIMEOUT));
    }
    CHECK(refused);
    CHECK(s.board.motor(0).mode == MotorMode::BRAKE);
    h.run(1000000);
    CHECK(s.fw->state() == SessionState::FAILSAFE);

    CONTEXT("re-ARM clears it; old setpoints are gone");
    const uint8_t aseq = h.send(arm_msg(s.fw->boot_id()));
    h.run(20000);
    CHECK(acked(h, proto::Arm::ID, aseq) || h.count<proto::Ack>() > 0);
    CHECK(s.fw->state() == SessionState::ARMED);
    CHECK(s.fw->failsafe_reason() == FailsafeReason::NONE);
    CHECK_EQ(s.fw->target(0), 0);

    CONTEXT("DISARM from FAILSAFE also clears the reason (table)");
    h.run(300000);
    CHECK(s.fw->state() == SessionState::FAILSAFE);
    h.send(proto::Disarm());
    h.run();
    CHECK(s.fw->state() == SessionState::DISARMED);
    CHECK(s.fw->failsafe_reason() == FailsafeReason::NONE);
}

static void test_watchdog_fed_by_valid_frames_only() {
    CONTEXT("valid frames of any kind feed the watchdog, rejected ones do not");
    Sim s(TB6612, 31);
    Host h(s);
    open_and_arm(s, h);
    // A wrong-direction (MCU-to-host) message is a valid frame: counted, feeds the watchdog.
    for (int i = 0; i < 20; ++i) {
        proto::Ack a = {1, 2};
        h.send(a);
        h.run(50000);
    }
    CHECK(s.fw->state() == SessionState::ARMED);
    // A frame whose payload the spec refuses (value error) is not valid.
    uint8_t payload[9] = {proto::PROTOCOL_VERSION, 0, 0, 0, 0, 0, 0, 9 /* bad FeedbackMode */, 0};
    for (int i = 0; i < 10; ++i) {
        uint8_t out[proto::MAX_FRAME];
        const size_t n =
            encode_frame(proto::Hello::ID, h.next_seq(), proto::Hello::CRC_EXTRA, payload, sizeof payload, out, sizeof out);
        h.set_next_seq(static_cast<uint8_t>(h.next_seq() + 1));
        s.feed(out, n);
        h.run(50000);
    }
    CHECK(s.fw->state() == SessionState::FAILSAFE);
    CHECK_EQ(s.fw->link().decoder().stats().value_errors, 10u);
}

static void test_safe_states() {
    CONTEXT("COAST");
    {
        Sim s(TB6612, 32);
        Host h(s);
        open_session(h);
        proto::SetConfig c = config_of(s);
        c.safe_state = proto::SafeState::COAST;
        h.send(c);
        h.send(arm_msg(s.fw->boot_id()));
        h.send(wheels(100, 100));
        h.run(30000);
        CHECK(s.board.motor(0).mode == MotorMode::DRIVE);
        h.send(proto::Disarm());
        h.run();
        CHECK(s.board.motor(0).mode == MotorMode::COAST && s.board.motor(1).mode == MotorMode::COAST);
        CHECK_EQ(s.board.motor(0).effort, 0);
    }
    CONTEXT("RAMP_DOWN: the PID follows a ramp to zero at the decel limit, then coasts");
    {
        Sim s(BTS7960, 33);
        Host h(s);
        open_and_arm(s, h, FeedbackMode::LOCKSTEP);
        Plant plants[2] = {Plant(config_of(s), 1200.0), Plant(config_of(s), 1200.0)};
        const proto::SetWheelSpeeds go = wheels(600, 600);
        run_plant(s, h, plants, 2, 1000, &go);
        CHECK(fabsf(s.fw->ramped(0) - 600.0f) < 0.01f);
        h.send(proto::Disarm());
        h.run();
        CHECK(s.fw->state() == SessionState::DISARMED);
        CHECK(s.board.motor(0).mode == MotorMode::DRIVE);  // still driving the ramp down
        const float before = s.fw->ramped(0);
        run_plant(s, h, plants, 2, 10, static_cast<const proto::SetWheelSpeeds*>(0));
        CHECK(fabsf(before - s.fw->ramped(0) - 30.0f) < 0.01f);  // 3000 mm/s^2 * 10 ms
        run_plant(s, h, plants, 2, 200, static_cast<const proto::SetWheelSpeeds*>(0));
        CHECK(s.fw->ramped(0) == 0.0f);
        CHECK(s.board.motor(0).mode == MotorMode::COAST && s.board.motor(1).mode == MotorMode::COAST);
        CHECK(plants[0].speed_mm_s < 150.0);  // followed the ramp down from 600 (with the motor's lag)
    }
}

static void test_encoder_fault() {
    CONTEXT("encoder fault: effort without counts for 0.5 s");
    Sim s(TB6612, 34);
    Host h(s);
    open_and_arm(s, h);
    const proto::SetWheelSpeeds go = wheels(300, 300);
    uint64_t fault_at = 0;
    for (int t = 0; t < 1500 && fault_at == 0; t += 10) {
        if (t % 50 == 0) {
            h.send(go);
        }
        h.run(10000);
        if (s.fw->state() == SessionState::FAILSAFE) {
            fault_at = s.time_us();
        }
    }
    CHECK(fault_at > 0);
    CHECK(s.fw->failsafe_reason() == FailsafeReason::ENCODER_FAULT);
    CHECK(s.fw->status() & proto::Status::ENCODER_FAULT);
    CHECK(s.board.motor(0).mode == MotorMode::BRAKE);
    // |u| >= 300 from the first ramp steps (feed-forward + P), so the fault comes ~0.5 s in.
    CHECK(fault_at >= 500000 && fault_at <= 800000);
    h.send(arm_msg(s.fw->boot_id()));
    h.run();
    CHECK(!(s.fw->status() & proto::Status::ENCODER_FAULT));
}

// -------------------------------------------------------------------------------------------------
// Control loop

static void test_pid_converges() {
    CONTEXT("PID step response against a first-order motor (tb6612 defaults)");
    Sim s(TB6612, 40);
    Host h(s);
    open_and_arm(s, h);
    Plant plants[2] = {Plant(config_of(s)), Plant(config_of(s))};
    const proto::SetWheelSpeeds go = wheels(300, 300);
    std::vector<double> trace;
    run_plant(s, h, plants, 2, 2500, &go, &trace);
    double peak = 0;
    for (size_t i = 0; i < trace.size(); ++i) {
        peak = trace[i] > peak ? trace[i] : peak;
    }
    double lo = 1e9, hi = -1e9, mean = 0;
    for (size_t i = trace.size() - 500; i < trace.size(); ++i) {
        lo = trace[i] < lo ? trace[i] : lo;
        hi = trace[i] > hi ? trace[i] : hi;
        mean += trace[i] / 500.0;
    }
    CHECK(fabs(mean - 300.0) < 6.0);       // settles on target (2 %)
    CHECK(hi - lo < 15.0);                 // no sustained oscillation (encoder quantisation only)
    CHECK(peak < 300.0 * 1.15);            // bounded overshoot
    CHECK(fabs(plants[1].speed_mm_s + 300.0) < 10.0);  // wheel 1: wired the other way round ...
    CHECK(s.board.motor(1).effort < 0);    // ... motor_invert bit 1 reverses the driver ...
    CHECK(s.fw->counts(1) > 0);            // ... and encoder_invert bit 1 the count
    CHECK(s.fw->effort(1) > 0);
    proto::Feedback fb;
    CHECK(h.last(fb));
    CHECK(fb.encoder_counts[1] > 0 && abs(fb.wheel_speed_mm_s[0] - 300) < 30);
    CHECK(!(fb.status & proto::Status::SATURATED));
    CHECK(s.fw->state() == SessionState::ARMED);

    CONTEXT("standstill: target 0 and ramp at 0 -> effort 0, integrator cleared");
    const proto::SetWheelSpeeds stop = wheels(0, 0);
    run_plant(s, h, plants, 2, 1000, &stop);
    CHECK_EQ(s.fw->effort(0), 0);
    CHECK(s.fw->integral(0) == 0.0f);
    CHECK(s.board.motor(0).mode == MotorMode::DRIVE && s.board.motor(0).effort == 0);
}

static void test_anti_windup_recovery() {
    CONTEXT("anti-windup: long saturation, then recovery without a big overshoot");
    Sim s(TB6612, 41);
    Host h(s);
    open_and_arm(s, h);
    Plant plants[2] = {Plant(config_of(s), 250.0), Plant(config_of(s), 250.0)};  // heavily loaded
    const proto::SetWheelSpeeds go = wheels(400, 400);
    run_plant(s, h, plants, 2, 1500, &go);
    proto::Feedback fb;
    CHECK(h.last(fb) && (fb.status & proto::Status::SATURATED));
    CHECK_EQ(s.fw->effort(0), 1000);
    // Conditional integration stops where the output saturates: kf*r + ks + kp*e + I = max, with
    // e = 400 - 250 here, instead of winding up to the clamp (1000).
    const proto::SetPid pid = TB6612.default_pid();
    CHECK(s.fw->integral(0) < 1000.0f - pid.kf * 400 - pid.ks - pid.kp * 150 + 20.0f);
    plants[0].gain_mm_s = plants[1].gain_mm_s = 700.0;  // load removed
    std::vector<double> trace;
    run_plant(s, h, plants, 2, 1500, &go, &trace);
    double peak = 0;
    for (size_t i = 0; i < trace.size(); ++i) {
        peak = trace[i] > peak ? trace[i] : peak;
    }
    CHECK(peak < 400.0 * 1.3);
    CHECK(fabs(trace.back() - 400.0) < 10.0);
    double settled_at = 0;
    for (size_t i = 0; i < trace.size(); ++i) {
        if (fabs(trace[i] - 400.0) > 12.0) {
            settled_at = static_cast<double>(i + 1) / 1000.0;
        }
    }
    CHECK(settled_at < 1.0);  // within 3 % for good after at most 1 s
}

static void test_output_limits() {
    CONTEXT("max_effort_permille holds on every output");
    Sim s(TB6612, 42);
    Host h(s);
    open_session(h);
    proto::SetConfig c = config_of(s);
    c.max_effort_permille = 400;
    h.send(c);
    h.send(arm_msg(s.fw->boot_id()));
    h.run();
    Plant plants[2] = {Plant(config_of(s)), Plant(config_of(s))};
    const proto::SetWheelSpeeds go = wheels(600, -600);
    int worst = 0;
    for (int i = 0; i < 100; ++i) {
        run_plant(s, h, plants, 2, 10, i % 5 == 0 ? &go : static_cast<const proto::SetWheelSpeeds*>(0));
        for (uint8_t w = 0; w < 2; ++w) {
            const int e = abs(s.board.motor(w).effort);
            worst = e > worst ? e : worst;
        }
    }
    CHECK(worst <= 400);
    CHECK_EQ(worst, 400);
    CHECK(s.fw->status() & proto::Status::SATURATED);
}

static void test_ramp_in_loop() {
    CONTEXT("setpoints ramp at accel_limit, slow down and reverse at decel_limit");
    Sim s(TB6612, 43);  // accel 1000 mm/s^2 (10 per tick), decel 2000 (20 per tick)
    Host h(s);
    open_and_arm(s, h, FeedbackMode::STREAM, 0, 2000);
    quiet_pid(h);
    h.send(wheels(300, 0));
    h.run();
    std::vector<float> seen;
    for (int i = 0; i < 35; ++i) {
        h.run(10000);
        seen.push_back(s.fw->ramped(0));
    }
    bool ok = true;
    for (size_t i = 0; i < seen.size(); ++i) {
        const float want = static_cast<float>(i + 1) * 10.0f > 300.0f ? 300.0f : static_cast<float>(i + 1) * 10.0f;
        ok = ok && fabsf(seen[i] - want) < 0.01f;
    }
    CHECK(ok);
    h.send(wheels(-100, 0));
    h.run();
    seen.clear();
    for (int i = 0; i < 30; ++i) {
        h.run(10000);
        seen.push_back(s.fw->ramped(0));
    }
    // 300 -> 0 in 15 ticks of 20, then -10 per tick to -100.
    CHECK(fabsf(seen[0] - 280.0f) < 0.01f);
    CHECK(fabsf(seen[14] - 0.0f) < 0.01f);
    CHECK(fabsf(seen[15] + 10.0f) < 0.01f);
    CHECK(fabsf(seen[24] + 100.0f) < 0.01f);
    CHECK(fabsf(seen[29] + 100.0f) < 0.01f);
}

static void test_lockstep() {
    CONTEXT("lockstep: one FEEDBACK per applied setpoint, carrying its seq");
    Sim s(BTS7960, 44);
    Host h(s);
    open_and_arm(s, h, FeedbackMode::LOCKSTEP, 0, 2000);
    quiet_pid(h);
    h.clear();
    h.run(100000);
    CHECK_EQ(h.count<proto::Feedback>(), 0u);
    for (int k = 0; k < 20; ++k) {
        h.clear();
        const uint8_t seq = h.send(wheels(static_cast<int16_t>(10 * k), 0));
        h.run(10000);
        std::vector<proto::Feedback> fbs = h.all<proto::Feedback>();
        CHECK_EQ(fbs.size(), 1u);
        if (fbs.size() == 1) {
            CHECK_EQ(fbs[0].ack_seq, seq);
            CHECK_EQ(fbs[0].ack_tick, fbs[0].tick);
            CHECK(fbs[0].status & proto::Status::LOCKSTEP);
            CHECK_EQ(fbs[0].boot_id, s.fw->boot_id());
        }
    }
    CONTEXT("lockstep: setpoints in one tick queue (LOCKSTEP_QUEUE), one applied and answered per tick");
    static_assert(proto::LOCKSTEP_QUEUE == 2, "three setpoints overfill the queue by one");
    h.clear();
    const uint8_t first = h.send(wheels(50, 50));
    h.send(wheels(60, 60));  // superseded by the third: the queue is full
    const uint8_t third = h.send(wheels(70, 70));
    h.run(10000);
    std::vector<proto::Feedback> fbs = h.all<proto::Feedback>();
    CHECK_EQ(fbs.size(), 1u);
    CHECK(!fbs.empty() && fbs[0].ack_seq == first);
    CHECK_EQ(s.fw->target(0), 50);
    h.clear();
    h.run(10000);
    fbs = h.all<proto::Feedback>();
    CHECK_EQ(fbs.size(), 1u);
    CHECK(!fbs.empty() && fbs[0].ack_seq == third);
    CHECK_EQ(s.fw->target(0), 70);
    h.clear();
    h.run(10000);
    CHECK_EQ(h.count<proto::Feedback>(), 0u);  // the queue is empty: no FEEDBACK
    CONTEXT("lockstep: a refused setpoint gets a NACK and no FEEDBACK");
    h.clear();
    const uint8_t bad = h.send(wheels(5000, 0));
    h.run(20000);
    CHECK(nacked(h, proto::SetWheelSpeeds::ID, bad, NackReason::OUT_OF_RANGE, 0));
    CHECK_EQ(h.count<proto::Feedback>(), 0u);
}

// FEEDBACKs `ticks` apart, each with the status bits in `want` and none in `not_want`.
static bool spaced(const std::vector<proto::Feedback>& fbs, uint16_t ticks, uint8_t want, uint8_t not_want) {
    for (size_t k = 0; k < fbs.size(); ++k) {
        if ((fbs[k].status & want) != want || (fbs[k].status & not_want) != 0) {
            return false;
        }
        if (k > 0 && static_cast<uint16_t>(fbs[k].tick - fbs[k - 1].tick) != ticks) {
            return false;
        }
    }
    return true;
}

static void test_lockstep_out_of_armed() {
    using proto::Status;
    const uint8_t session = Status::SESSION | Status::LOCKSTEP;
    CONTEXT("lockstep, DISARMED: FEEDBACK streams at the session's feedback_hz");
    Sim s(BTS7960, 45);
    Host h(s);
    s.advance_us(5000);  // requests between ticks
    open_session(h, FeedbackMode::LOCKSTEP, 25, 100);
    quiet_pid(h);
    h.clear();
    h.run(1000000);
    std::vector<proto::Feedback> fbs = h.all<proto::Feedback>();
    CHECK_EQ(fbs.size(), 25u);
    CHECK(spaced(fbs, 4, session, Status::ARMED | Status::FAILSAFE));

    CONTEXT("lockstep, ARMED: none without a setpoint, exactly one per applied setpoint");
    h.send(arm_msg(s.fw->boot_id()));
    h.run();
    CHECK(s.fw->state() == SessionState::ARMED);
    h.clear();
    h.run(40000);  // within the 100 ms watchdog
    CHECK_EQ(h.count<proto::Feedback>(), 0u);
    uint16_t applied_tick = 0;
    for (int k = 0; k < 5; ++k) {
        h.clear();
        const uint8_t seq = h.send(wheels(static_cast<int16_t>(20 * k), 0));
        h.run(10000);
        fbs = h.all<proto::Feedback>();
        CHECK_EQ(fbs.size(), 1u);
        CHECK(!fbs.empty() && fbs[0].ack_seq == seq && (fbs[0].status & Status::ARMED));
        applied_tick = fbs.empty() ? 0 : fbs[0].tick;
    }

    CONTEXT("lockstep, DISARM: the first FEEDBACK in the first tick out of ARMED, then at feedback_hz");
    h.clear();
    const uint8_t disarm = h.send(proto::Disarm());
    h.run();
    CHECK(acked(h, proto::Disarm::ID, disarm) && s.fw->state() == SessionState::DISARMED);
    h.clear();
    h.run(1000000);
    fbs = h.all<proto::Feedback>();
    CHECK_EQ(fbs.size(), 25u);
    CHECK(!fbs.empty() && fbs[0].tick == static_cast<uint16_t>(applied_tick + 1));
    CHECK(spaced(fbs, 4, session, Status::ARMED | Status::FAILSAFE));

    CONTEXT("lockstep, armed again: back to one per setpoint at once, none without");
    h.send(arm_msg(s.fw->boot_id()));
    h.run();
    h.clear();
    h.run(40000);
    CHECK_EQ(h.count<proto::Feedback>(), 0u);
    for (int k = 0; k < 3; ++k) {
        h.clear();
        const uint8_t seq = h.send(wheels(0, static_cast<int16_t>(20 * k)));
        h.run(10000);
        fbs = h.all<proto::Feedback>();
        CHECK_EQ(fbs.size(), 1u);
        CHECK(!fbs.empty() && fbs[0].ack_seq == seq && fbs[0].tick == fbs[0].ack_tick);
    }

    CONTEXT("lockstep, FAILSAFE: the watchdog's tick sends one, then FEEDBACK streams at feedback_hz");
    h.clear();
    h.run(1000000);  // no setpoint: the 100 ms watchdog expires
    CHECK(s.fw->state() == SessionState::FAILSAFE);
    fbs = h.all<proto::Feedback>();
    CHECK(fbs.size() >= 22u && fbs.size() <= 23u);  // 0.9 s at 25 Hz after the watchdog's 0.1 s
    CHECK(spaced(fbs, 4, session | Status::FAILSAFE, Status::ARMED));
    CHECK(!fbs.empty() && fbs[0].failsafe_reason == FailsafeReason::COMM_TIMEOUT);
}

static void test_stream_rates() {
    struct Case {
        uint8_t hz;
        unsigned per_second;
        unsigned spacing_ticks;
    };
    const Case cases[] = {{25, 25, 4}, {30, 34, 3}, {40, 34, 3}, {100, 100, 1}, {0, 50, 2}, {255, 100, 1}, {1, 1, 100}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        CONTEXT("stream at %u Hz", cases[i].hz);
        Sim s(TB6612, 50);
        Host h(s);
        s.advance_us(5000);  // HELLO between ticks
        open_session(h, FeedbackMode::STREAM, cases[i].hz);
        h.clear();
        h.run(1000000);
        std::vector<proto::Feedback> fbs = h.all<proto::Feedback>();
        CHECK_EQ(fbs.size(), cases[i].per_second);
        bool even = true;
        for (size_t k = 1; k < fbs.size(); ++k) {
            even = even && static_cast<uint16_t>(fbs[k].tick - fbs[k - 1].tick) == cases[i].spacing_ticks &&
                   fbs[k].mcu_time_us - fbs[k - 1].mcu_time_us == cases[i].spacing_ticks * 10000u;
        }
        CHECK(even);
    }
}

static void test_feedback_contents() {
    CONTEXT("FEEDBACK carries this tick's counts, speeds, efforts and the applied setpoint");
    Sim s(TB6612, 51);
    Host h(s);
    open_and_arm(s, h, FeedbackMode::STREAM, 100);
    const uint8_t seq = h.send(wheels(100, 100));
    h.run(10000);
    s.board.add_encoder(0, 78);    // 1005 mm/s over the next tick
    s.board.add_encoder(1, -39);   // raw, inverted by the config: +502 mm/s
    h.clear();
    h.run(10000);
    proto::Feedback fb;
    CHECK(h.last(fb));
    CHECK_EQ(fb.ack_seq, seq);
    CHECK_EQ(fb.encoder_counts[0], 78);
    CHECK_EQ(fb.encoder_counts[1], 39);
    CHECK_EQ(fb.wheel_speed_mm_s[0], 1005);
    CHECK_EQ(fb.wheel_speed_mm_s[1], 503);  // 502.65 rounds to 503
    CHECK_EQ(fb.effort_permille[0], s.fw->effort(0));
    CHECK_EQ(fb.steering_mrad, 0);
    CHECK_EQ(fb.mcu_time_us % 10000u, 0u);
    CHECK_EQ(fb.status, proto::Status::SESSION | proto::Status::ARMED | proto::Status::CONFIG_DEFAULTS);

    CONTEXT("RESET_ODOMETRY: counts to 0, no speed spike");
    h.send(proto::ResetOdometry());
    h.run(10000);
    CHECK_EQ(s.fw->counts(0), 0);
    CHECK(h.last(fb) && fb.encoder_counts[0] == 0 && fb.wheel_speed_mm_s[0] == 0);

    CONTEXT("changing encoder_invert flips the count but not the measured speed");
    s.board.add_encoder(1, -39);
    h.run(10000);
    CHECK_EQ(s.fw->measured(1), 503);
    proto::SetConfig c = config_of(s);
    c.encoder_invert = 0;
    h.send(c);
    h.run(10000);
    CHECK_EQ(s.fw->measured(1), 0);
    CHECK_EQ(s.fw->counts(1), -39);
}

static void test_steering_and_esc() {
    CONTEXT("picar: steering quantised, reported back in FEEDBACK");
    Sim s(PICAR, 60);
    Host h(s);
    open_and_arm(s, h, FeedbackMode::STREAM, 100, 2000);
    const int16_t mrads[] = {300, -300, 1571, -1571, 100, 0};
    const uint16_t pulses[] = {1667, 1333, 1833, 1222, 1500, 1500};
    const int16_t backs[] = {262, -262, 524, -436, 0, 0};
    for (size_t i = 0; i < 6; ++i) {
        h.send(ackermann(0, mrads[i]));
        h.clear();
        h.run(10000);
        CHECK_EQ(s.board.steering_us(), pulses[i]);
        proto::Feedback fb;
        CHECK(h.last(fb) && fb.steering_mrad == backs[i]);
    }

    CONTEXT("picar: the ESC stays neutral for esc_arm_ms after boot, ARM is accepted");
    h.send(ackermann(1000, 300));
    h.run(10000);
    CHECK(s.fw->state() == SessionState::ARMED);
    Plant plant[1] = {Plant(config_of(s), 2500.0)};
    const proto::SetAckermann go = ackermann(1000, 300);
    while (s.time_us() < 2990000) {
        run_plant(s, h, plant, 1, 10, &go);
        CHECK_EQ(s.board.esc_us(), 1500);
        CHECK_EQ(s.fw->effort(0), 0);
    }
    CHECK_EQ(s.board.steering_us(), 1667);  // steering works during the window
    run_plant(s, h, plant, 1, 30, &go);
    CHECK(s.board.esc_us() > 1500);
    run_plant(s, h, plant, 1, 1500, &go);
    CHECK(s.board.esc_us() <= 1800);  // max_effort 600 -> at most 1500 + 0.6 * 500
    CHECK(fabs(plant[0].speed_mm_s - 1000.0) < 60.0);

    CONTEXT("picar: failsafe -> ESC neutral, steering centred");
    h.run(2100000);
    CHECK(s.fw->state() == SessionState::FAILSAFE);
    CHECK_EQ(s.board.esc_us(), 1500);
    CHECK_EQ(s.board.steering_us(), 1500);
}

static void test_lights_in_loop() {
    CONTEXT("tb6612 turn signals follow the motion state");
    Sim s(TB6612, 61);
    Host h(s);
    std::set<uint8_t> seen;
    for (int i = 0; i < 100; ++i) {
        h.run(10000);
        seen.insert(s.board.lights_mask());
    }
    const uint8_t FRONT = Lights::FRONT_LEFT | Lights::FRONT_RIGHT;
    const uint8_t REAR = Lights::REAR_LEFT | Lights::REAR_RIGHT;
    CHECK(seen.size() == 2 && seen.count(FRONT) && seen.count(REAR));
    open_and_arm(s, h, FeedbackMode::STREAM, 0, 2000);
    quiet_pid(h);
    h.send(wheels(100, 300));
    seen.clear();
    for (int i = 0; i < 100; ++i) {
        h.run(10000);
        seen.insert(s.board.lights_mask());
    }
    CHECK(seen.size() == 2 && seen.count(0) && seen.count(Lights::FRONT_LEFT | Lights::REAR_LEFT));
    h.send(wheels(-200, 200));
    seen.clear();
    for (int i = 0; i < 100; ++i) {
        h.run(10000);
        seen.insert(s.board.lights_mask());
    }
    CHECK(seen.size() == 2 && seen.count(0) && seen.count(FRONT | REAR));
    Sim car(PICAR, 61);
    CHECK_EQ(car.board.lights_calls(), 0u);  // no TURN_SIGNALS capability
}

// -------------------------------------------------------------------------------------------------
// EEPROM

static void test_eeprom_round_trip() {
    Sim s(TB6612, 70);
    Host h(s);
    open_session(h);
    CONTEXT("SAVE_CONFIG, power cycle, the config and gains come back");
    proto::SetConfig c = config_of(s);
    c.accel_limit_mm_s2 = 777;
    c.safe_state = proto::SafeState::COAST;
    c.wheel_diameter_um = 70000;
    c.feedback_hz = 20;
    h.send(c);
    proto::SetPid p = {1, 1.5f, 2.5f, 0.5f, 1.75f, 60.0f};
    h.send(p);
    const uint8_t seq = h.send(proto::SaveConfig());
    h.run();
    CHECK(acked(h, proto::SaveConfig::ID, seq));
    CHECK(!(s.fw->status() & proto::Status::CONFIG_DEFAULTS));
    const uint32_t writes = s.board.eeprom_writes();
    const uint8_t again = h.send(proto::SaveConfig());
    h.run();
    CHECK(acked(h, proto::SaveConfig::ID, again));
    CHECK_EQ(s.board.eeprom_writes(), writes);  // unchanged bytes are not rewritten

    s.power_cycle();
    h.resync_mcu_seq();
    h.clear();
    h.run(20000);
    CHECK_EQ(h.count<proto::Log>(), 0u);
    CHECK(!(s.fw->status() & proto::Status::CONFIG_DEFAULTS));
    CHECK_EQ(s.fw->config().accel_limit_mm_s2, 777);
    CHECK(s.fw->config().safe_state == proto::SafeState::COAST);
    CHECK_EQ(s.fw->config().wheel_diameter_um, 70000u);
    CHECK(s.fw->gains(1).kp == 1.5f && s.fw->gains(1).kf == 1.75f && s.fw->gains(1).ks == 60.0f);
    CHECK(s.fw->gains(0).kp == TB6612.default_pid().kp);
    proto::Identity id;
    CHECK(h.last(id) && id.feedback_hz == 20);
    CHECK_EQ(h.count<proto::Feedback>(), 1u);  // IDLE stream at the saved rate: 20 Hz

    CONTEXT("SAVE_CONFIG refused while ARMED; EEPROM write failure reported");
    open_and_arm(s, h);
    uint8_t sseq = h.send(proto::SaveConfig());
    h.run();
    CHECK(nacked(h, proto::SaveConfig::ID, sseq, NackReason::ARMED));
    h.send(proto::Disarm());
    c.accel_limit_mm_s2 = 778;
    h.send(c);
    h.run();
    s.board.set_eeprom_write_fails(true);
    sseq = h.send(proto::SaveConfig());
    h.run();
    CHECK(nacked(h, proto::SaveConfig::ID, sseq, NackReason::EEPROM_ERROR));
    s.board.set_eeprom_write_fails(false);
    s.board.set_eeprom_write_xor(0x04);  // writes "succeed" but the cells hold other bits
    sseq = h.send(proto::SaveConfig());
    h.run();
    CHECK(nacked(h, proto::SaveConfig::ID, sseq, NackReason::EEPROM_ERROR));
    s.board.set_eeprom_write_xor(0);
    CHECK_EQ(h.count<proto::Log>(), 0u);  // the EEPROM stall does not log "late"
}

static std::string boot_log(Sim& s, Host& h) {
    s.power_cycle();
    h.resync_mcu_seq();
    h.clear();
    h.run();
    proto::Log log;
    return h.last(log) ? std::string(log.text, log.text_len) : std::string();
}

static void test_eeprom_corruption() {
    Sim s(BTS7960, 71);
    Host h(s);
    open_session(h);
    proto::SetConfig c = config_of(s);
    c.max_wheel_speed_mm_s = 900;
    h.send(c);
    h.send(proto::SaveConfig());
    h.run();
    CONTEXT("a good image loads silently");
    CHECK(boot_log(s, h).empty());
    CHECK_EQ(s.fw->config().max_wheel_speed_mm_s, 900);

    for (uint16_t off = 0; off < config::IMAGE_SIZE; off = static_cast<uint16_t>(off + 7)) {
        CONTEXT("one flipped bit at image offset %u -> defaults, LOG, status bit", off);
        s.board.corrupt_eeprom(static_cast<uint16_t>(config::IMAGE_ADDR + off), 0x10);
        const std::string text = boot_log(s, h);
        CHECK(!text.empty());
        CHECK(text.find("defaults") != std::string::npos);
        CHECK(s.fw->status() & proto::Status::CONFIG_DEFAULTS);
        CHECK_EQ(s.fw->config().max_wheel_speed_mm_s, BTS7960.default_config().max_wheel_speed_mm_s);
        std::vector<proto::Log> logs = h.all<proto::Log>();
        CHECK(logs.size() == 1 && logs[0].level == proto::LogLevel::WARN);
        CHECK(h.frames.size() >= 2 && h.frames[0].id == proto::Identity::ID && h.frames[1].id == proto::Log::ID);
        s.board.corrupt_eeprom(static_cast<uint16_t>(config::IMAGE_ADDR + off), 0x10);  // repair
        CHECK(boot_log(s, h).empty());
    }
    CONTEXT("the causes are told apart");
    s.board.corrupt_eeprom(config::IMAGE_ADDR + 2, 0xFF);  // version byte
    CHECK(boot_log(s, h).find("no EEPROM image") != std::string::npos);
    s.board.corrupt_eeprom(config::IMAGE_ADDR + 2, 0xFF);
    s.board.corrupt_eeprom(config::IMAGE_ADDR + 20, 0x01);
    CHECK(boot_log(s, h).find("CRC") != std::string::npos);
    s.board.corrupt_eeprom(config::IMAGE_ADDR + 20, 0x01);

    CONTEXT("a good CRC over inconsistent values -> defaults");
    proto::SetConfig bad = BTS7960.default_config();
    bad.servo_min_us = bad.servo_max_us;
    control::Gains g[2] = {{1, 1, 0, 1, 0}, {1, 1, 0, 1, 0}};
    uint8_t scratch[proto::MAX_FRAME];
    CHECK(config::save(s.board, bad, g, scratch));
    CHECK(boot_log(s, h).find("invalid") != std::string::npos);
    CHECK(s.fw->status() & proto::Status::CONFIG_DEFAULTS);

    CONTEXT("an erased EEPROM");
    s.board.erase_eeprom();
    CHECK(boot_log(s, h).find("no EEPROM image") != std::string::npos);
}

// -------------------------------------------------------------------------------------------------
// Link statistics, timing robustness

static Bytes frame_bytes(uint8_t id, uint8_t seq, uint8_t crc_extra, const uint8_t* payload, uint8_t len) {
    uint8_t out[proto::MAX_FRAME];
    const size_t n = encode_frame(id, seq, crc_extra, payload, len, out, sizeof out);
    return Bytes(out, out + n);
}

static void test_link_stats() {
    CONTEXT("LINK_STATS counters");
    Sim s(TB6612, 80);
    Host h(s);
    h.set_next_seq(10);
    open_session(h);  // seq 10: seq accounting restarts after it
    proto::Ping ping = {0};
    h.send_seq(ping, 20);  // first frame after HELLO: no gap counted
    h.send_seq(ping, 21);
    h.send_seq(ping, 24);  // 22, 23 missing: 2
    h.send_seq(ping, 24);  // a retry: nothing
    h.send_seq(ping, 22);  // backwards: (22 - 25) mod 256 = 253
    uint32_t discarded = 0;
    // A CRC error.
    Bytes bad_crc = frame_bytes(proto::Ping::ID, 23, proto::Ping::CRC_EXTRA ^ 1, reinterpret_cast<const uint8_t*>("abcd"), 4);
    discarded += static_cast<uint32_t>(bad_crc.size() - 1);
    h.raw(bad_crc);
    // COBS error: a code byte promising more bytes than the chunk has.
    const Bytes bad_cobs = {0x05, 0x11, 0x22, 0x00};
    discarded += 3;
    h.raw(bad_cobs);
    // Unknown id.
    Bytes unknown = frame_bytes(0x7E, 23, 0x00, reinterpret_cast<const uint8_t*>("x"), 1);
    discarded += static_cast<uint32_t>(unknown.size() - 1);
    h.raw(unknown);
    // Length error: ARM with 2 bytes.
    Bytes short_arm = frame_bytes(proto::Arm::ID, 23, proto::Arm::CRC_EXTRA, reinterpret_cast<const uint8_t*>("xy"), 2);
    discarded += static_cast<uint32_t>(short_arm.size() - 1);
    h.raw(short_arm);
    // Value error: HELLO with feedback_mode 7.
    const uint8_t hp[9] = {1, 0, 0, 0, 0, 0, 0, 7, 0};
    Bytes bad_value = frame_bytes(proto::Hello::ID, 23, proto::Hello::CRC_EXTRA, hp, 9);
    discarded += static_cast<uint32_t>(bad_value.size() - 1);
    h.raw(bad_value);
    // A duplicate reliable request.
    h.send_seq(proto::GetConfig(), 23);
    h.send_seq(proto::GetConfig(), 23);
    h.run();
    const uint32_t frames_before = static_cast<uint32_t>(h.frames.size());
    const uint8_t seq = 24;
    h.send_seq(proto::GetLinkStats(), seq);
    h.run();
    proto::LinkStats st;
    CHECK(h.last(st));
    CHECK_EQ(st.req_seq, seq);
    CHECK_EQ(st.frames_ok, 1u + 5u + 2u + 1u);  // HELLO, 5 PINGs, 2 GET_CONFIG, GET_LINK_STATS
    CHECK_EQ(st.crc_errors, 1u);
    CHECK_EQ(st.cobs_errors, 1u);
    CHECK_EQ(st.unknown_ids, 1u);
    CHECK_EQ(st.length_errors, 1u);
    CHECK_EQ(st.value_errors, 1u);
    CHECK_EQ(st.bytes_discarded, discarded);
    CHECK_EQ(st.seq_gaps, 2u + 253u + 0u + 0u);  // 23 after 22: none; 23 again: a retry; 24: none
    CHECK_EQ(st.duplicates, 1u);
    CHECK_EQ(st.rx_overruns, 0u);
    CHECK_EQ(st.frames_sent, frames_before);  // every frame before this reply
    CHECK_EQ(h.mcu_seq_gaps(), 0u);
}

static void test_late_polls() {
    CONTEXT("poll() late: missed ticks skipped, one LOG, the tick grid kept");
    Sim s(TB6612, 81);
    Host h(s);
    open_session(h, FeedbackMode::STREAM, 100);
    h.clear();
    s.poll_interval_us = 35000;  // 3.5 ticks between polls
    h.run(350000);
    CHECK(s.fw->ticks_skipped() > 0);
    std::vector<proto::Log> logs = h.all<proto::Log>();
    CHECK(logs.size() >= 1 && logs.size() <= 2);  // at most one per second
    CHECK(!logs.empty() && std::string(logs[0].text, logs[0].text_len) == "control: poll() late, ticks skipped: 2");
    s.poll_interval_us = 1000;
    h.clear();
    h.run(100000);
    std::vector<proto::Feedback> fbs = h.all<proto::Feedback>();
    bool grid = fbs.size() >= 9;
    for (size_t i = 0; i < fbs.size(); ++i) {
        grid = grid && fbs[i].mcu_time_us % 10000u == 0;
    }
    CHECK(grid);
}

static void test_micros_wrap() {
    CONTEXT("micros() wraps: ticks, watchdog and uptime carry on");
    Sim s(TB6612, 82);
    s.boot_micros = 0xFFFFFFFFu - 700000u;
    s.power_cycle();
    Host h(s);
    h.run();
    open_and_arm(s, h, FeedbackMode::STREAM, 100);
    quiet_pid(h);
    const proto::SetWheelSpeeds go = wheels(50, 50);
    h.clear();
    for (int i = 0; i < 30; ++i) {  // 1.5 s across the wrap, setpoints every 50 ms
        h.send(go);
        h.run(50000);
        CHECK(s.fw->state() == SessionState::ARMED);
    }
    std::vector<proto::Feedback> fbs = h.all<proto::Feedback>();
    CHECK(fbs.size() >= 149 && fbs.size() <= 151);
    bool even = true;
    for (size_t k = 1; k < fbs.size(); ++k) {
        even = even && static_cast<uint32_t>(fbs[k].mcu_time_us - fbs[k - 1].mcu_time_us) == 10000u;
    }
    CHECK(even);
    h.run(300000);
    CHECK(s.fw->state() == SessionState::FAILSAFE);
    open_session(h);
    proto::Identity id;
    CHECK(h.last(id));
    CHECK(id.uptime_ms > 0xFFFFFFFFu / 1000u);  // past the point where micros() wrapped
}

// A robot without encoders or EEPROM: open loop, no config persistence.
static proto::SetConfig bare_config() { return TB6612.default_config(); }
static proto::SetPid bare_pid() { return TB6612.default_pid(); }
static const Robot BARE = {"Bare", proto::Board::UNO, proto::Capability::DIFF_DRIVE, FeedbackMode::STREAM,
                           bare_config, bare_pid, proto::LightsMode::AUTO};

static void test_bare_robot() {
    CONTEXT("no ENCODERS: open loop (feed-forward); no EEPROM: defaults silently, SAVE unsupported");
    Sim s(BARE, 90);
    Host h(s);
    h.run();
    CHECK_EQ(h.count<proto::Log>(), 0u);
    CHECK(!(s.fw->status() & proto::Status::CONFIG_DEFAULTS));
    CHECK_EQ(s.board.eeprom_writes(), 0u);
    open_and_arm(s, h);
    const uint8_t seq = h.send(proto::SaveConfig());
    h.run();
    CHECK(nacked(h, proto::SaveConfig::ID, seq, NackReason::ARMED));
    h.send(wheels(300, -300));
    h.run(500000);
    CHECK(s.fw->state() == SessionState::FAILSAFE);  // only one setpoint: the watchdog ran out
    h.send(arm_msg(s.fw->boot_id()));
    const proto::SetWheelSpeeds go = wheels(300, -300);
    for (int i = 0; i < 10; ++i) {
        h.send(go);
        h.run(50000);
    }
    const proto::SetPid pid = TB6612.default_pid();
    const int16_t ff = static_cast<int16_t>(control::round_half_away(pid.kf * 300 + pid.ks));  // kf*r + ks
    CHECK_EQ(s.fw->effort(0), ff);
    CHECK_EQ(s.fw->effort(1), -ff);
    CHECK(s.fw->state() == SessionState::ARMED);  // no encoder fault without encoders
    h.send(proto::Disarm());
    const uint8_t s2 = h.send(proto::SaveConfig());
    h.run();
    CHECK(nacked(h, proto::SaveConfig::ID, s2, NackReason::UNSUPPORTED));
}

// -------------------------------------------------------------------------------------------------
// Robustness: random streams of garbage and valid frames

static uint32_t g_rng = 0x2545F491u;
static uint32_t rnd() {
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 17;
    g_rng ^= g_rng << 5;
    return g_rng;
}

static void random_frame(Sim& s, Host& h) {
    switch (rnd() % 14) {
    case 0: h.send(hello(static_cast<FeedbackMode>(rnd() % 2), static_cast<uint8_t>(rnd()), static_cast<uint16_t>(rnd()))); break;
    case 1: h.send(arm_msg(rnd() % 4 ? s.fw->boot_id() : rnd())); break;
    case 2: h.send(proto::Disarm()); break;
    case 3: h.send(wheels(static_cast<int16_t>(rnd() % 1400) - 700, static_cast<int16_t>(rnd() % 1400) - 700)); break;
    case 4: h.send(ackermann(static_cast<int16_t>(rnd() % 5000) - 2500, static_cast<int16_t>(rnd() % 4000) - 2000)); break;
    case 5: {
        proto::SetConfig c = s.fw->config();
        c.max_effort_permille = static_cast<uint16_t>(rnd() % 1200);
        c.safe_state = static_cast<proto::SafeState>(rnd() % 3);
        c.feedback_hz = static_cast<uint8_t>(rnd() % 120);
        c.encoder_invert = static_cast<uint8_t>(rnd() % 4);
        h.send(c);
        break;
    }
    case 6: {
        proto::SetPid p = {static_cast<uint8_t>(rnd() % 3), (rnd() % 300) / 100.0f, (rnd() % 1000) / 100.0f, 0.0f,
                           (rnd() % 300) / 100.0f, static_cast<float>(rnd() % 100)};
        h.send(p);
        break;
    }
    case 7: h.send(proto::GetLinkStats()); break;
    case 8: h.send(proto::SaveConfig()); break;
    case 9: h.send(proto::ResetOdometry()); break;
    case 10: { proto::Ping p = {rnd()}; h.send(p); break; }
    case 11: { proto::GetPid g = {static_cast<uint8_t>(rnd() % 3)}; h.send(g); break; }
    case 12: h.send_seq(proto::GetConfig(), static_cast<uint8_t>(h.next_seq() - 1)); break;
    default: {
        Bytes junk(rnd() % 90);
        for (size_t i = 0; i < junk.size(); ++i) {
            junk[i] = static_cast<uint8_t>(rnd() % 3 == 0 ? 0 : rnd());
        }
        h.raw(junk);
    }
    }
}

static void test_random_streams() {
    for (int p = 0; p < sim_profiles::count(); ++p) {
        const sim_profiles::Profile* prof = sim_profiles::at(p);
        CONTEXT("random host streams on %s", prof->name);
        Sim s(*prof->robot, 1000 + static_cast<uint32_t>(p));
        Host h(s);
        bool ok = true;
        for (int i = 0; i < 3000; ++i) {
            const uint32_t n = rnd() % 3;
            for (uint32_t k = 0; k < n; ++k) {
                random_frame(s, h);
            }
            if (rnd() % 8 == 0) {
                s.board.add_encoder(static_cast<uint8_t>(rnd() % 2), static_cast<int32_t>(rnd() % 200) - 100);
            }
            if (rnd() % 500 == 0) {
                s.power_cycle();
                h.resync_mcu_seq();
            }
            h.run(rnd() % 30000);
            const SessionState st = s.fw->state();
            ok = ok && (st == SessionState::IDLE || st == SessionState::DISARMED || st == SessionState::ARMED ||
                        st == SessionState::FAILSAFE);
            const bool ramping = s.fw->ramped(0) != 0.0f || s.fw->ramped(1) != 0.0f;
            for (uint8_t w = 0; w < 2; ++w) {
                ok = ok && abs(s.fw->effort(w)) <= 1000 && abs(s.board.motor(w).effort) <= 1000;
                // Out of ARMED the motors are only driven while a RAMP_DOWN is under way.
                if (st != SessionState::ARMED && !ramping) {
                    ok = ok && (s.board.motor(w).mode != MotorMode::DRIVE || s.board.motor(w).effort == 0);
                }
            }
            ok = ok && (st == SessionState::FAILSAFE) == (s.fw->failsafe_reason() != FailsafeReason::NONE);
            if (!ok) {
                printf("random stream invariant broken at step %d (state %d)\n", i, static_cast<int>(st));
                break;
            }
        }
        CHECK(ok);
        CHECK_EQ(h.mcu_seq_gaps(), 0u);
        CHECK_EQ(h.rx_stats().crc_errors + h.rx_stats().cobs_errors + h.rx_stats().length_errors, 0u);
    }
}

static void test_c_api() {
    CONTEXT("C API (the ctypes library's entry points)");
    CHECK_EQ(rl_sim_profile_count(), 3);
    CHECK(std::string(rl_sim_profile_name(2)) == "picar");
    CHECK(rl_sim_profile_name(3) == 0);
    CHECK(rl_sim_create("no-such-robot", 1) == 0);
    CHECK(rl_sim_create("3", 1) == 0);
    rl_sim* by_index = rl_sim_create("2", 1);
    CHECK(by_index != 0);
    rl_sim_destroy(by_index);
    rl_sim* a = rl_sim_create("DiffDriveBTS7960", 5);
    rl_sim* b = rl_sim_create("diffdrive-bts7960", 5);
    CHECK(a != 0 && b != 0);
    uint8_t buf[4096];
    const size_t na = rl_sim_read_mcu_bytes(a, buf, sizeof buf);
    CHECK(na > 0);
    // Garbage through the C API, with ASan watching.
    for (int i = 0; i < 500; ++i) {
        uint8_t junk[64];
        for (size_t k = 0; k < sizeof junk; ++k) {
            junk[k] = static_cast<uint8_t>(rnd());
        }
        rl_sim_feed_host_bytes(a, junk, rnd() % sizeof junk);
        rl_sim_add_encoder(a, static_cast<uint8_t>(rnd() % 3), 5);
        rl_sim_advance_us(a, rnd() % 20000);
        rl_sim_read_mcu_bytes(a, buf, sizeof buf);
    }
    std::vector<uint8_t> out(rl_sim_outputs_size() + 16, 0xAB);
    rl_sim_get_outputs(a, reinterpret_cast<rl_sim_outputs*>(out.data()));
    CHECK(out[rl_sim_outputs_size()] == 0xAB);  // wrote exactly its size
    uint8_t e[4] = {1, 2, 3, 4};
    CHECK(rl_sim_eeprom_write(a, 1020, e, 4) == 1);
    CHECK(rl_sim_eeprom_write(a, 1021, e, 4) == 0);
    uint8_t r[4] = {0};
    CHECK(rl_sim_eeprom_read(a, 1020, r, 4) == 1 && memcmp(r, e, 4) == 0);
    rl_sim_reset(a);
    CHECK(rl_sim_read_mcu_bytes(a, buf, sizeof buf) > 0);
    rl_sim_destroy(a);
    rl_sim_destroy(b);
    rl_sim_destroy(0);
}

int main() {
    test_rounding();
    test_ramp_math();
    test_pid_math();
    test_measure_math();
    test_steering_math();
    test_pulse_math();
    test_lights_math();
    test_config_validation();
    test_boot_announcement();
    test_handshake_bytes();
    test_hello_rejected();
    test_arm_and_setpoint_refusals();
    test_ackermann_refusals();
    test_ping();
    test_one_frame_per_poll();
    test_reset_new_boot_id();
    test_duplicates();
    test_pid_requests();
    test_config_requests();
    test_watchdog_timing();
    test_failsafe_latched();
    test_watchdog_fed_by_valid_frames_only();
    test_safe_states();
    test_encoder_fault();
    test_pid_converges();
    test_anti_windup_recovery();
    test_output_limits();
    test_ramp_in_loop();
    test_lockstep();
    test_lockstep_out_of_armed();
    test_stream_rates();
    test_feedback_contents();
    test_steering_and_esc();
    test_lights_in_loop();
    test_eeprom_round_trip();
    test_eeprom_corruption();
    test_link_stats();
    test_late_polls();
    test_micros_wrap();
    test_bare_robot();
    test_random_streams();
    test_c_api();
    printf("%u passed, %u failed\n", g_passed, g_failed);
    return g_failed == 0 ? 0 : 1;
}
