// DO NOT EDIT: generated from protocol/spec/robots.toml and protocol/spec/roverlink.toml by `python -m protocol generate`.
// spec hash: 0x163FE6FE
// Defaults of the AckermannPiCar example (picar): Ackermann PiCar: Uno, brushless drive motor behind an ESC (calibrated at boot), one motor encoder, steering servo 65..125 degrees in 15 degree steps, stream feedback.
// Change them over the link (SET_CONFIG, SET_PID) and SAVE_CONFIG, or edit robots.toml.
#ifndef ROVERLINK_EXAMPLE_ACKERMANNPICAR_PROFILE_H
#define ROVERLINK_EXAMPLE_ACKERMANNPICAR_PROFILE_H

#include <RoverLink.h>

namespace robot_profile {

static const char NAME[] = "AckermannPiCar";
static const roverlink::proto::Board BOARD = roverlink::proto::Board::UNO;
static const uint16_t CAPABILITIES = roverlink::proto::Capability::ACKERMANN | roverlink::proto::Capability::ENCODERS | roverlink::proto::Capability::STEERING_SERVO | roverlink::proto::Capability::ESC | roverlink::proto::Capability::EEPROM;
static const roverlink::proto::FeedbackMode FEEDBACK_MODE = roverlink::proto::FeedbackMode::STREAM;

// Built in code, not kept as a static struct: on AVR that would cost SRAM for the whole run.
// static: two profiles linked into one test program must not merge.
static inline roverlink::proto::SetConfig default_config() {
    roverlink::proto::SetConfig c;
    c.watchdog_ms = 250;
    c.safe_state = roverlink::proto::SafeState::BRAKE;
    c.accel_limit_mm_s2 = 2000;
    c.decel_limit_mm_s2 = 4000;
    c.max_wheel_speed_mm_s = 2000;
    c.max_effort_permille = 600;
    c.encoder_cpr = 720;
    c.encoder_invert = 0;
    c.motor_invert = 0;
    c.wheel_diameter_um = 65000;
    c.steering_center_cdeg = 9000;
    c.steering_min_cdeg = 6500;
    c.steering_max_cdeg = 12500;
    c.steering_step_cdeg = 1500;
    c.servo_min_us = 500;
    c.servo_max_us = 2500;
    c.esc_min_us = 1000;
    c.esc_neutral_us = 1500;
    c.esc_max_us = 2000;
    c.esc_arm_ms = 3000;
    c.feedback_hz = 50;
    return c;
}

static inline roverlink::proto::SetPid default_pid() {
    roverlink::proto::SetPid p;
    p.wheel = roverlink::proto::PID_ALL_WHEELS;
    p.kp = 0.3f;
    p.ki = 1.5f;
    p.kd = 0.0f;
    p.kf = 0.4f;
    return p;
}

}  // namespace robot_profile

#endif  // ROVERLINK_EXAMPLE_ACKERMANNPICAR_PROFILE_H
