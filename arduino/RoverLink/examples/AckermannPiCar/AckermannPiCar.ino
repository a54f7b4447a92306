// AckermannPiCar: an Ackermann-steered car on an Arduino Uno.
//
// A brushless motor behind an RC ESC, a steering servo (65..125 degrees, centre 90, 15 degree
// steps), one quadrature encoder on the motor (x4, on the Uno's two external interrupt pins)
// for the speed PID, stream feedback. Defaults are in robot_profile.h, generated from
// protocol/spec/robots.toml. Wiring, timers and flashing: docs/firmware.md, "Boards, wiring and
// flashing".
//
// The ESC gets neutral pulses from boot and nothing else for esc_arm_ms (3 s): the arming /
// calibration window most car ESCs need. Keep the wheels off the ground the first time.
#include <RoverLink.h>

#include "robot_profile.h"

namespace rl = roverlink::avr;

// ESC and servo pulses are made by Timer1 in hardware (50 Hz, 0.5 us steps): pins 9 and 10 only.
const rl::PulseChannel ESC = rl::PulseChannel::A;       // pin 9, OC1A
const rl::PulseChannel STEERING = rl::PulseChannel::B;  // pin 10, OC1B

// Motor encoder on INT0 and INT1.
const uint8_t ENC_A = 2;
const uint8_t ENC_B = 3;
static_assert(digitalPinToInterrupt(ENC_A) != NOT_AN_INTERRUPT && digitalPinToInterrupt(ENC_B) != NOT_AN_INTERRUPT,
              "encoder pins must be external interrupt pins (Uno: 2 and 3)");

const uint8_t UNCONNECTED_ANALOG = A0;  // noise for the per-boot random boot_id: leave it open

rl::QuadratureEncoder motor_encoder(ENC_A, ENC_B);
rl::AckermannBoard<rl::Timer1> board(motor_encoder, ESC, STEERING, UNCONNECTED_ANALOG);

static const roverlink::Robot ROBOT = {robot_profile::NAME,          robot_profile::BOARD,
                                       robot_profile::CAPABILITIES,  robot_profile::FEEDBACK_MODE,
                                       robot_profile::default_config, robot_profile::default_pid};
roverlink::Firmware firmware(Serial, board, ROBOT);

void motor_encoder_edge() { motor_encoder.on_edge(); }

void setup() {
    board.begin();  // Timer1 taken over, ESC and servo lines held low until the firmware starts
    motor_encoder.attach_external(motor_encoder_edge);
    Serial.begin(115200);
    firmware.begin();  // ESC neutral and steering centre from here on
}

void loop() { firmware.poll(); }
