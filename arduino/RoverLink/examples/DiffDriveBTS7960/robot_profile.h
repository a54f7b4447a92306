// DO NOT EDIT: generated from protocol/robots/diffdrive-bts7960.toml by `python -m protocol generate`.
// spec hash: 0xBDF31659
// Defaults of diffdrive-bts7960 (DiffDriveBTS7960 example): 3D-printed SLAM robot: Mega 2560, two BTS7960 drivers (RPWM/LPWM), 19.2:1 gearmotors with 64 CPR encoders, lockstep command/feedback.
// Change them over the link (SET_CONFIG, SET_PID) and SAVE_CONFIG, or edit protocol/robots/diffdrive-bts7960.toml.
#ifndef ROVERLINK_EXAMPLE_DIFFDRIVEBTS7960_PROFILE_H
#define ROVERLINK_EXAMPLE_DIFFDRIVEBTS7960_PROFILE_H

#include <RoverLink.h>

namespace robot_profile {

static const char NAME[] = "DiffDriveBTS7960";
static const roverlink::proto::Board BOARD = roverlink::proto::Board::MEGA2560;
static const uint16_t CAPABILITIES = roverlink::proto::Capability::DIFF_DRIVE | roverlink::proto::Capability::ENCODERS | roverlink::proto::Capability::EEPROM | roverlink::proto::Capability::LOCKSTEP;
static const roverlink::proto::FeedbackMode FEEDBACK_MODE = roverlink::proto::FeedbackMode::LOCKSTEP;
static const roverlink::proto::LightsMode LIGHTS_MODE = roverlink::proto::LightsMode::AUTO;  // turn signals at power-up

// Wiring (protocol/robots/diffdrive-bts7960.toml): Arduino pin numbers (A<n> as its number on this board).
static const uint8_t LEFT_RPWM = 2;  // left motor, BTS7960 rpwm
static const uint8_t LEFT_LPWM = 3;  // left motor, BTS7960 lpwm
static const uint8_t LEFT_R_EN = 22;  // left motor, BTS7960 r_en
static const uint8_t LEFT_L_EN = 23;  // left motor, BTS7960 l_en
static const uint8_t RIGHT_RPWM = 6;  // right motor, BTS7960 rpwm
static const uint8_t RIGHT_LPWM = 7;  // right motor, BTS7960 lpwm
static const uint8_t RIGHT_R_EN = 24;  // right motor, BTS7960 r_en
static const uint8_t RIGHT_L_EN = 25;  // right motor, BTS7960 l_en
static const uint8_t LEFT_ENC_A = 62;  // left encoder, channel a (A8)
static const uint8_t LEFT_ENC_B = 63;  // left encoder, channel b (A9)
static const uint8_t RIGHT_ENC_A = 64;  // right encoder, channel a (A10)
static const uint8_t RIGHT_ENC_B = 65;  // right encoder, channel b (A11)
static const uint8_t ENTROPY_PIN = 54;  // entropy, leave unconnected: its ADC noise seeds the boot_id (A0)

// The configuration as a SET_CONFIG payload in flash, unpacked when asked for: a static struct
// would cost SRAM for the whole run on AVR, and code setting each field more flash than this.
// static: two profiles linked into one test program must not merge.
static const uint8_t DEFAULT_CONFIG[] ROVERLINK_PROGMEM = {
    0xFA, 0x00,  // watchdog_ms = 250
    0x02,  // safe_state = RAMP_DOWN
    0xDC, 0x05,  // accel_limit_mm_s2 = 1500
    0xB8, 0x0B,  // decel_limit_mm_s2 = 3000
    0xE8, 0x03,  // max_wheel_speed_mm_s = 1000
    0xE8, 0x03,  // max_effort_permille = 1000
    0xC0, 0x04,  // encoder_cpr = 1216
    0x00,  // encoder_invert = 0
    0x00,  // motor_invert = 0
    0x90, 0x5F, 0x01, 0x00,  // wheel_diameter_um = 90000
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
    0x64,  // feedback_hz = 100
};
static_assert(sizeof DEFAULT_CONFIG == roverlink::proto::SetConfig::PAYLOAD_SIZE, "a SET_CONFIG payload");

static inline roverlink::proto::SetConfig default_config() {
    uint8_t payload[sizeof DEFAULT_CONFIG];
    for (uint8_t i = 0; i < sizeof payload; ++i) {
        payload[i] = ROVERLINK_READ_BYTE(DEFAULT_CONFIG + i);
    }
    roverlink::proto::SetConfig c = roverlink::proto::SetConfig();
    roverlink::proto::unpack(payload, sizeof payload, c);  // valid: protocol/robots/diffdrive-bts7960.toml is checked
    return c;
}

static inline roverlink::proto::SetPid default_pid() {
    roverlink::proto::SetPid p;
    p.wheel = roverlink::proto::PID_ALL_WHEELS;
    p.kp = 0.6f;
    p.ki = 4.0f;
    p.kd = 0.0f;
    p.kf = 0.62f;
    p.ks = 62.0f;
    return p;
}

}  // namespace robot_profile

#endif  // ROVERLINK_EXAMPLE_DIFFDRIVEBTS7960_PROFILE_H
