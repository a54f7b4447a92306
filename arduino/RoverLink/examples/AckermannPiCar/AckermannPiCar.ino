// AckermannPiCar: an Ackermann-steered car on an Arduino Uno.
//
// A brushless motor behind an RC ESC, a steering servo (65..125 degrees, centre 90, 15 degree
// steps), one quadrature encoder on the motor (x4, on the Uno's two external interrupt pins)
// for the speed PID, stream feedback. Defaults are in robot_profile.h, generated from
// protocol/robots/picar.toml. Wiring, timers and flashing: docs/firmware.md, "Boards, wiring and
// flashing".
//
// The ESC gets neutral pulses from boot and nothing else for esc_arm_ms (3 s): the arming /
// calibration window most car ESCs need. Keep the wheels off the ground the first time.
#include <RoverLink.h>

#include "robot_profile.h"

namespace rl = roverlink::avr;

// Pins: robot_profile.h, generated from picar.toml (docs/robots.md, "Wiring").
// ESC and servo pulses are made by Timer1 in hardware (50 Hz, 0.5 us steps): on the Uno, pins 9
// (OC1A) and 10 (OC1B) only.
static_assert(rl::Timer1::has_pin(robot_profile::ESC_PIN) && rl::Timer1::has_pin(robot_profile::STEERING_PIN),
              "the ESC and the steering servo must be on Timer1's pins (Uno: 9 and 10)");
const rl::PulseChannel ESC = rl::Timer1::channel_of(robot_profile::ESC_PIN);
const rl::PulseChannel STEERING = rl::Timer1::channel_of(robot_profile::STEERING_PIN);

// Motor encoder on INT0 and INT1.
static_assert(digitalPinToInterrupt(robot_profile::MOTOR_ENC_A) != NOT_AN_INTERRUPT &&
                  digitalPinToInterrupt(robot_profile::MOTOR_ENC_B) != NOT_AN_INTERRUPT,
              "encoder pins must be external interrupt pins (Uno: 2 and 3)");

rl::QuadratureEncoder motor_encoder(robot_profile::MOTOR_ENC_A, robot_profile::MOTOR_ENC_B);
rl::AckermannBoard<rl::Timer1> board(motor_encoder, ESC, STEERING, robot_profile::ENTROPY_PIN);

static const roverlink::Robot ROBOT = {robot_profile::NAME,          robot_profile::BOARD,
                                       robot_profile::CAPABILITIES,  robot_profile::FEEDBACK_MODE,
                                       robot_profile::default_config, robot_profile::default_pid,
                                       robot_profile::LIGHTS_MODE};
roverlink::Firmware firmware(Serial, board, ROBOT);

void motor_encoder_edge() { motor_encoder.on_edge(); }

void setup() {
    board.begin();  // Timer1 taken over, ESC and servo lines held low until the firmware starts
    motor_encoder.attach_external(motor_encoder_edge);
    Serial.begin(115200);
    firmware.begin();  // ESC neutral and steering centre from here on
}

void loop() { firmware.poll(); }
