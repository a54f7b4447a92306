// DO NOT EDIT: generated from protocol/robots/diffdrive-tb6612.toml by `python -m protocol generate`.
// spec hash: 0xBDF31659
// Defaults of diffdrive-tb6612 (DiffDriveTB6612 example): ros_arduino_bridge-style differential-drive car: Mega 2560, TB6612 (or L298N), two quadrature encoders, four turn-signal LEDs, stream feedback.
// Change them over the link (SET_CONFIG, SET_PID) and SAVE_CONFIG, or edit protocol/robots/diffdrive-tb6612.toml.
#ifndef ROVERLINK_EXAMPLE_DIFFDRIVETB6612_PROFILE_H
#define ROVERLINK_EXAMPLE_DIFFDRIVETB6612_PROFILE_H

#include <RoverLink.h>

namespace robot_profile {

static const char NAME[] = "DiffDriveTB6612";
static const roverlink::proto::Board BOARD = roverlink::proto::Board::MEGA2560;
static const uint16_t CAPABILITIES = roverlink::proto::Capability::DIFF_DRIVE | roverlink::proto::Capability::ENCODERS | roverlink::proto::Capability::EEPROM | roverlink::proto::Capability::TURN_SIGNALS | roverlink::proto::Capability::LOCKSTEP;
static const roverlink::proto::FeedbackMode FEEDBACK_MODE = roverlink::proto::FeedbackMode::STREAM;
static const roverlink::proto::LightsMode LIGHTS_MODE = roverlink::proto::LightsMode::AUTO;  // turn signals at power-up

// Wiring (protocol/robots/diffdrive-tb6612.toml): Arduino pin numbers (A<n> as its number on this board).
static const uint8_t LEFT_PWM = 6;  // left motor, TB6612 pwm
static const uint8_t LEFT_IN1 = 22;  // left motor, TB6612 in1
static const uint8_t LEFT_IN2 = 23;  // left motor, TB6612 in2
static const uint8_t LEFT_STANDBY = 26;  // left motor, TB6612 standby
static const uint8_t RIGHT_PWM = 7;  // right motor, TB6612 pwm
static const uint8_t RIGHT_IN1 = 24;  // right motor, TB6612 in1
static const uint8_t RIGHT_IN2 = 25;  // right motor, TB6612 in2
static const uint8_t RIGHT_STANDBY = 26;  // right motor, TB6612 standby
static const uint8_t LEFT_ENC_A = 2;  // left encoder, channel a
static const uint8_t LEFT_ENC_B = 3;  // left encoder, channel b
static const uint8_t RIGHT_ENC_A = 18;  // right encoder, channel a
static const uint8_t RIGHT_ENC_B = 19;  // right encoder, channel b
static const uint8_t LED_FRONT_LEFT = 30;  // LED front left
static const uint8_t LED_FRONT_RIGHT = 31;  // LED front right
static const uint8_t LED_REAR_LEFT = 32;  // LED rear left
static const uint8_t LED_REAR_RIGHT = 33;  // LED rear right
static const uint8_t ENTROPY_PIN = 54;  // entropy, leave unconnected: its ADC noise seeds the boot_id (A0)

// Motor PWM pins whose driver runs above the core's frequency (protocol/spec/hardware.toml):
// the sketch sets each one's timer to 31373 Hz (pwm_ultrasonic), whichever timer it is on.
static const uint8_t FAST_PWM_PINS[] = {6, 7};
static const uint8_t FAST_PWM_PIN_COUNT = 2;

// The configuration as a SET_CONFIG payload in flash, unpacked when asked for: a static struct
// would cost SRAM for the whole run on AVR, and code setting each field more flash than this.
// static: two profiles linked into one test program must not merge.
static const uint8_t DEFAULT_CONFIG[] ROVERLINK_PROGMEM = {
    0xFA, 0x00,  // watchdog_ms = 250
    0x01,  // safe_state = BRAKE
    0xE8, 0x03,  // accel_limit_mm_s2 = 1000
    0xD0, 0x07,  // decel_limit_mm_s2 = 2000
    0x58, 0x02,  // max_wheel_speed_mm_s = 600
    0xE8, 0x03,  // max_effort_permille = 1000
    0x18, 0x06,  // encoder_cpr = 1560
    0x02,  // encoder_invert = 2
    0x02,  // motor_invert = 2
    0x00, 0xFA, 0x00, 0x00,  // wheel_diameter_um = 64000
    0x28, 0x23,  // steering_center_cdeg = 9000
    0x28, 0x23,  // steering_min_cdeg = 9000
    0x28, 0x23,  // steering_max_cdeg = 9000
    0x00, 0x00,  // steering_step_cdeg = 0
    0xF4, 0x01,  // servo_min_us = 500
    0xC4, 0x09,  // servo_max_us = 2500
    0xE8, 0x03,  // esc_min_us = 1000
    0xDC, 0x05,  // esc_neutral_us = 1500
    0xD0, 0x07,  // esc_max_us = 2000
    0x00, 0x00,  // esc_arm_ms = 0
    0x32,  // feedback_hz = 50
};
static_assert(sizeof DEFAULT_CONFIG == roverlink::proto::SetConfig::PAYLOAD_SIZE, "a SET_CONFIG payload");

static inline roverlink::proto::SetConfig default_config() {
    uint8_t payload[sizeof DEFAULT_CONFIG];
    for (uint8_t i = 0; i < sizeof payload; ++i) {
        payload[i] = ROVERLINK_READ_BYTE(DEFAULT_CONFIG + i);
    }
    roverlink::proto::SetConfig c = roverlink::proto::SetConfig();
    roverlink::proto::unpack(payload, sizeof payload, c);  // valid: protocol/robots/diffdrive-tb6612.toml is checked
    return c;
}

static inline roverlink::proto::SetPid default_pid() {
    roverlink::proto::SetPid p;
    p.wheel = roverlink::proto::PID_ALL_WHEELS;
    p.kp = 1.0f;
    p.ki = 6.0f;
    p.kd = 0.0f;
    p.kf = 1.25f;
    p.ks = 70.0f;
    return p;
}

}  // namespace robot_profile

#endif  // ROVERLINK_EXAMPLE_DIFFDRIVETB6612_PROFILE_H
