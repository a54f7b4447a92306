// The control law of docs/control.md as pure functions: no state, no I/O, so each piece is tested
// on its own (tests/firmware/native/core/test_core.cpp) and the Firmware class only sequences them.
#ifndef ROVERLINK_CORE_CONTROL_H
#define ROVERLINK_CORE_CONTROL_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "../generated/roverlink_protocol.h"

namespace roverlink {
namespace control {

static const float PI_F = 3.14159265358979f;
static const uint32_t TICK_US = 1000000UL / proto::CONTROL_RATE_HZ;  // 10 000
static const float DT_S = 1.0f / static_cast<float>(proto::CONTROL_RATE_HZ);

static_assert(1000000UL % proto::CONTROL_RATE_HZ == 0, "the control period must be whole microseconds");

// Round half away from zero (docs/control.md: "rounding everywhere").
int32_t round_half_away(float x);
// round(x * (whole + frac / 2^32)) for 0 <= x <= 18000, in integers: exact for the two angle
// conversions below (the error, x * 2^-33, stays under the nearest distance to a tie).
uint32_t mul_round(uint16_t x, uint8_t whole, uint32_t frac);
// The same, saturated to an int16 (NaN gives 0): for speeds and efforts.
int16_t round_to_i16(float x);
// Integer a / b rounded half away from zero (b > 0).
int32_t div_round(int32_t a, int32_t b);

struct Gains {
    float kp;  // permille per mm/s
    float ki;  // permille per mm (per second of error)
    float kd;  // permille per mm/s^2, on the measurement
    float kf;  // permille per mm/s of setpoint (feed-forward)
    float ks;  // permille with the setpoint's sign (static-friction feed-forward)
};

// SET_PID's five gains are a Gains (the same floats in the same order): copied as one block.
static_assert(sizeof(Gains) == 5 * sizeof(float) &&
                  offsetof(proto::SetPid, ks) - offsetof(proto::SetPid, kp) == 4 * sizeof(float) &&
                  sizeof(proto::SetPid::kp) == sizeof(float) && sizeof(proto::SetPid::ks) == sizeof(float),
              "SET_PID's kp..ks must be laid out as control::Gains");
inline void gains_from(Gains& g, const proto::SetPid& p) {
    memcpy(&g, reinterpret_cast<const uint8_t*>(&p) + offsetof(proto::SetPid, kp), sizeof g);
}
inline void gains_to(proto::SetPid& p, const Gains& g) {
    memcpy(reinterpret_cast<uint8_t*>(&p) + offsetof(proto::SetPid, kp), &g, sizeof g);
}

// One wheel's velocity PID (section 4.6) on r = ramped setpoint and m = measured speed (mm/s).
// `integral` is the controller's memory and `saturated` is set when the output was clamped. The
// integrator is first held within +-max_effort (a lowered limit bounds it at once), then
// conditionally integrated after the output is computed. Returns u, rounded, in -max..max.
int16_t pid_step(const Gains& g, float r, int16_t m, int16_t m_prev, float max_effort, float& integral,
                 bool& saturated);

// Section 4.4: the targets `t` re-limited to +-max_speed; when either is beyond it, both are scaled
// by max_speed / peak (rounded half away from zero), so a turn keeps its curvature.
void limit_targets(int16_t (&t)[proto::WHEEL_COUNT], uint16_t max_speed);

// Ramp (section 4.5), in integers of 0.01 mm/s, where a limit in mm/s^2 times dt (10 ms) is the
// limit itself: `ramped` moved toward `target` by at most `up` (speeding up in the same direction,
// or from 0) or `down` (slowing down or reversing).
int32_t ramp_step(int32_t ramped, int32_t target, uint16_t up, uint16_t down);
static const int32_t RAMP_UNITS_PER_MM_S = 100;
static_assert(proto::CONTROL_RATE_HZ == RAMP_UNITS_PER_MM_S, "the integer ramp assumes dt = 10 ms");

// Wheel-rim speed in mm/s from a count delta over `periods` control periods, where
// `mm_s_per_count` = pi * wheel_diameter_um / 1000 / encoder_cpr / dt.
float mm_s_per_count(const proto::SetConfig& c);
int16_t measure_speed(int32_t delta_counts, float mm_s_per_count, uint16_t periods);

// Steering (section 3): servo angle in centidegrees for a front-wheel angle in mrad, clamped and
// quantised; and the angle reported back for a servo angle.
uint16_t steering_cdeg(int16_t mrad, const proto::SetConfig& c);
int16_t steering_mrad(uint16_t cdeg, const proto::SetConfig& c);

// Pulse widths (section 4.7).
uint16_t servo_pulse_us(uint16_t cdeg, const proto::SetConfig& c);
uint16_t esc_pulse_us(int16_t effort_permille, const proto::SetConfig& c);

// Turn-signal lights (docs/firmware.md, "Lights"): FAILSAFE's fast blink in every mode, else as
// `host` (SET_LIGHTS) says: in AUTO from the motion state, in OFF none, in MANUAL its steady, slow
// (1.5 Hz) and fast (3 Hz) lamps. `blink` counts control ticks modulo BLINK_PERIOD_TICKS.
// `left`/`right` are the wheel speed targets in effect, `steer_cdeg` the servo offset from centre
// (positive: left), used when `ackermann`.
static const uint8_t BLINK_PERIOD_TICKS = 66;  // 0.66 s at 100 Hz: 1.5 Hz
uint8_t lights_for(const proto::SetLights& host, proto::SessionState state, int16_t left, int16_t right,
                   int16_t steer_cdeg, bool ackermann, uint8_t blink);

}  // namespace control
}  // namespace roverlink

#endif  // ROVERLINK_CORE_CONTROL_H
