// DO NOT EDIT: generated from protocol/robots/picar.toml by `python -m protocol generate`.
// spec hash: 0xBDF31659
// Defaults of picar (AckermannPiCar example): Ackermann PiCar: Uno, brushless drive motor behind an ESC (calibrated at boot), one motor encoder, steering servo 65..125 degrees in 15 degree steps, stream feedback.
// Change them over the link (SET_CONFIG, SET_PID) and SAVE_CONFIG, or edit protocol/robots/picar.toml.
#ifndef ROVERLINK_EXAMPLE_ACKERMANNPICAR_PROFILE_H
#define ROVERLINK_EXAMPLE_ACKERMANNPICAR_PROFILE_H

#include <RoverLink.h>

namespace robot_profile {

static const char NAME[] = "AckermannPiCar";
static const roverlink::proto::Board BOARD = roverlink::proto::Board::UNO;
static const uint16_t CAPABILITIES = roverlink::proto::Capability::ACKERMANN | roverlink::proto::Capability::ENCODERS | roverlink::proto::Capability::STEERING_SERVO | roverlink::proto::Capability::ESC | roverlink::proto::Capability::EEPROM;
static const roverlink::proto::FeedbackMode FEEDBACK_MODE = roverlink::proto::FeedbackMode::STREAM;
static const roverlink::proto::LightsMode LIGHTS_MODE = roverlink::proto::LightsMode::AUTO;  // turn signals at power-up

// Wiring (protocol/robots/picar.toml): Arduino pin numbers (A<n> as its number on this board).
static const uint8_t MOTOR_ENC_A = 2;  // motor encoder, channel a
static const uint8_t MOTOR_ENC_B = 3;  // motor encoder, channel b
static const uint8_t ESC_PIN = 9;  // ESC signal
static const uint8_t STEERING_PIN = 10;  // steering servo signal
static const uint8_t ENTROPY_PIN = 14;  // entropy, leave unconnected: its ADC noise seeds the boot_id (A0)

// The configuration as a SET_CONFIG payload in flash, unpacked when asked for: a static struct
// would cost SRAM for the whole run on AVR, and code setting each field more flash than this.
// static: two profiles linked into one test program must not merge.
static const uint8_t DEFAULT_CONFIG[] ROVERLINK_PROGMEM = {
    0xFA, 0x00,  // watchdog_ms = 250
    0x01,  // safe_state = BRAKE
    0xD0, 0x07,  // accel_limit_mm_s2 = 2000
    0xA0, 0x0F,  // decel_limit_mm_s2 = 4000
    0xD0, 0x07,  // max_wheel_speed_mm_s = 2000
    0x58, 0x02,  // max_effort_permille = 600
    0xD0, 0x02,  // encoder_cpr = 720
    0x00,  // encoder_invert = 0
    0x00,  // motor_invert = 0
    0xE8, 0xFD, 0x00, 0x00,  // wheel_diameter_um = 65000
    0x28, 0x23,  // steering_center_cdeg = 9000
    0x64, 0x19,  // steering_min_cdeg = 6500
    0xD4, 0x30,  // steering_max_cdeg = 12500
    0xDC, 0x05,  // steering_step_cdeg = 1500
    0xF4, 0x01,  // servo_min_us = 500
    0xC4, 0x09,  // servo_max_us = 2500
    0xE8, 0x03,  // esc_min_us = 1000
    0xDC, 0x05,  // esc_neutral_us = 1500
    0xD0, 0x07,  // esc_max_us = 2000
    0xB8, 0x0B,  // esc_arm_ms = 3000
    0x32,  // feedback_hz = 50
};
static_assert(sizeof DEFAULT_CONFIG == roverlink::proto::SetConfig::PAYLOAD_SIZE, "a SET_CONFIG payload");

static inline roverlink::proto::SetConfig default_config() {
    uint8_t payload[sizeof DEFAULT_CONFIG];
    for (uint8_t i = 0; i < sizeof payload; ++i) {
        payload[i] = ROVERLINK_READ_BYTE(DEFAULT_CONFIG + i);
    }
    roverlink::proto::SetConfig c = roverlink::proto::SetConfig();
    roverlink::proto::unpack(payload, sizeof payload, c);  // valid: protocol/robots/picar.toml is checked
    return c;
}

static inline roverlink::proto::SetPid default_pid() {
    roverlink::proto::SetPid p;
    p.wheel = roverlink::proto::PID_ALL_WHEELS;
    p.kp = 0.3f;
    p.ki = 1.5f;
    p.kd = 0.0f;
    p.kf = 0.33f;
    p.ks = 85.0f;
    return p;
}

}  // namespace robot_profile

#endif  // ROVERLINK_EXAMPLE_ACKERMANNPICAR_PROFILE_H
