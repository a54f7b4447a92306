// DO NOT EDIT: generated from protocol/spec/robots.toml and protocol/spec/roverlink.toml by `python -m protocol generate`.
// spec hash: 0x163FE6FE
// Defaults of the DiffDriveBTS7960 example (diffdrive-bts7960): 3D-printed SLAM robot: Mega 2560, two BTS7960 drivers (RPWM/LPWM), 19.2:1 gearmotors with 64 CPR encoders, lockstep command/feedback.
// Change them over the link (SET_CONFIG, SET_PID) and SAVE_CONFIG, or edit robots.toml.
#ifndef ROVERLINK_EXAMPLE_DIFFDRIVEBTS7960_PROFILE_H
#define ROVERLINK_EXAMPLE_DIFFDRIVEBTS7960_PROFILE_H

#include <RoverLink.h>

namespace robot_profile {

static const char NAME[] = "DiffDriveBTS7960";
static const roverlink::proto::Board BOARD = roverlink::proto::Board::MEGA2560;
static const uint16_t CAPABILITIES = roverlink::proto::Capability::DIFF_DRIVE | roverlink::proto::Capability::ENCODERS | roverlink::proto::Capability::EEPROM | roverlink::proto::Capability::LOCKSTEP;
static const roverlink::proto::FeedbackMode FEEDBACK_MODE = roverlink::proto::FeedbackMode::LOCKSTEP;

// Built in code, not kept as a static struct: on AVR that would cost SRAM for the whole run.
// static: two profiles linked into one test program must not merge.
static inline roverlink::proto::SetConfig default_config() {
    roverlink::proto::SetConfig c;
    c.watchdog_ms = 250;
    c.safe_state = roverlink::proto::SafeState::RAMP_DOWN;
    c.accel_limit_mm_s2 = 1500;
    c.decel_limit_mm_s2 = 3000;
    c.max_wheel_speed_mm_s = 1000;
    c.max_effort_permille = 1000;
    c.encoder_cpr = 1216;
    c.encoder_invert = 0;
    c.motor_invert = 0;
    c.wheel_diameter_um = 90000;
    c.steering_center_cdeg = 9000;
    c.steering_min_cdeg = 9000;
    c.steering_max_cdeg = 9000;
    c.steering_step_cdeg = 0;
    c.servo_min_us = 500;
    c.servo_max_us = 2500;
    c.esc_min_us = 1000;
    c.esc_neutral_us = 1500;
    c.esc_max_us = 2000;
    c.esc_arm_ms = 0;
    c.feedback_hz = 100;
    return c;
}

static inline roverlink::proto::SetPid default_pid() {
    roverlink::proto::SetPid p;
    p.wheel = roverlink::proto::PID_ALL_WHEELS;
    p.kp = 0.6f;
    p.ki = 4.0f;
    p.kd = 0.0f;
    p.kf = 0.75f;
    return p;
}

}  // namespace robot_profile

#endif  // ROVERLINK_EXAMPLE_DIFFDRIVEBTS7960_PROFILE_H
