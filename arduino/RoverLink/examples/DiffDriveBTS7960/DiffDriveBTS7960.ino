// DiffDriveBTS7960: the 3D-printed SLAM robot on an Arduino Mega 2560.
//
// Two 19.2:1 gearmotors, each on a BTS7960 (IBT-2) board, two quadrature encoders (x4, on
// pin-change interrupts), lockstep feedback: the host sends a setpoint and waits for the
// FEEDBACK that answers it. Defaults are in robot_profile.h, generated from
// protocol/robots/diffdrive-bts7960.toml. Wiring, timers and flashing: docs/firmware.md, "Boards, wiring and
// flashing".
#include <RoverLink.h>

#include "robot_profile.h"

namespace rl = roverlink::avr;

// Pins: robot_profile.h, generated from diffdrive-bts7960.toml (docs/robots.md, "Wiring"). PWM stays at the
// Arduino default (490 Hz on Timer3 and Timer4): the BTS7960 is specified up to 25 kHz only, so
// the 31.4 kHz of pwm_ultrasonic() would be out of spec. The encoders are on port K's pin-change
// interrupt (PCINT16..19, one vector: PCINT2_vect).
namespace pins = robot_profile;

rl::Bts7960Motor left_motor(pins::LEFT_RPWM, pins::LEFT_LPWM, pins::LEFT_R_EN, pins::LEFT_L_EN);
rl::Bts7960Motor right_motor(pins::RIGHT_RPWM, pins::RIGHT_LPWM, pins::RIGHT_R_EN, pins::RIGHT_L_EN);
rl::QuadratureEncoder left_encoder(pins::LEFT_ENC_A, pins::LEFT_ENC_B);
rl::QuadratureEncoder right_encoder(pins::RIGHT_ENC_A, pins::RIGHT_ENC_B);
rl::NoLights no_lights;
rl::DiffDriveBoard<rl::Bts7960Motor> board(left_motor, right_motor, left_encoder, right_encoder, no_lights,
                                           pins::ENTROPY_PIN);

static const roverlink::Robot ROBOT = {robot_profile::NAME,          robot_profile::BOARD,
                                       robot_profile::CAPABILITIES,  robot_profile::FEEDBACK_MODE,
                                       robot_profile::default_config, robot_profile::default_pid,
                                       robot_profile::LIGHTS_MODE};
roverlink::Firmware firmware(Serial, board, ROBOT);

// One vector for the whole port: each encoder looks at its own pins; one that did not move sees
// its old level again, which counts nothing.
ISR(PCINT2_vect) {
    left_encoder.on_edge();
    right_encoder.on_edge();
}

void setup() {
    board.begin();  // both BTS7960 disabled (coasting) before anything else runs
    left_encoder.enable_pin_change();
    right_encoder.enable_pin_change();
    Serial.begin(115200);
    firmware.begin();
}

void loop() { firmware.poll(); }
