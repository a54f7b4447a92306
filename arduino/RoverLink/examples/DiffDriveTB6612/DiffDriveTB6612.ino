// DiffDriveTB6612: the ros_arduino_bridge-style car on an Arduino Mega 2560.
//
// Two DC gearmotors on a TB6612FNG, two quadrature encoders (x4, on the external interrupt pins),
// four turn-signal LEDs, stream feedback. Defaults (64 mm wheels, 1560 counts/rev, PID gains...)
// are in robot_profile.h, generated from protocol/robots/diffdrive-tb6612.toml; change them over the link.
// Wiring, timers and flashing: docs/firmware.md, "Boards, wiring and flashing".
//
// Using an L298N instead: replace Tb6612Motor by L298nMotor, wire ENA/ENB to the PWM pins ([drive] motors)
// (jumpers off) and IN1..IN4 to the direction pins, and drop the STBY argument.
#include <RoverLink.h>

#include "robot_profile.h"

namespace rl = roverlink::avr;

// Pins: robot_profile.h, generated from diffdrive-tb6612.toml (docs/robots.md, "Wiring"). Each TB6612 PWM
// pin's timer is sped up to 31.4 kHz below (no motor whine; on the reference robot both are on
// Timer4); STBY is shared by both channels. The LEDs go through 330 ohm resistors to GND.
namespace pins = robot_profile;

// Encoders: all four channels on external interrupts (INT4, INT5, INT3, INT2).
static_assert(digitalPinToInterrupt(pins::LEFT_ENC_A) != NOT_AN_INTERRUPT &&
                  digitalPinToInterrupt(pins::LEFT_ENC_B) != NOT_AN_INTERRUPT &&
                  digitalPinToInterrupt(pins::RIGHT_ENC_A) != NOT_AN_INTERRUPT &&
                  digitalPinToInterrupt(pins::RIGHT_ENC_B) != NOT_AN_INTERRUPT,
              "encoder pins must be external interrupt pins (Mega 2560: 2, 3, 18, 19, 20, 21)");

rl::Tb6612Motor left_motor(pins::LEFT_PWM, pins::LEFT_IN1, pins::LEFT_IN2, pins::LEFT_STANDBY);
rl::Tb6612Motor right_motor(pins::RIGHT_PWM, pins::RIGHT_IN1, pins::RIGHT_IN2, pins::RIGHT_STANDBY);
rl::QuadratureEncoder left_encoder(pins::LEFT_ENC_A, pins::LEFT_ENC_B);
rl::QuadratureEncoder right_encoder(pins::RIGHT_ENC_A, pins::RIGHT_ENC_B);
rl::TurnSignalLeds leds(pins::LED_FRONT_LEFT, pins::LED_FRONT_RIGHT, pins::LED_REAR_LEFT, pins::LED_REAR_RIGHT);
rl::DiffDriveBoard<rl::Tb6612Motor, rl::TurnSignalLeds> board(left_motor, right_motor, left_encoder, right_encoder,
                                                              leds, pins::ENTROPY_PIN);

static const roverlink::Robot ROBOT = {robot_profile::NAME,          robot_profile::BOARD,
                                       robot_profile::CAPABILITIES,  robot_profile::FEEDBACK_MODE,
                                       robot_profile::default_config, robot_profile::default_pid,
                                       robot_profile::LIGHTS_MODE};
roverlink::Firmware firmware(Serial, board, ROBOT);

void left_encoder_edge() { left_encoder.on_edge(); }
void right_encoder_edge() { right_encoder.on_edge(); }

void setup() {
    board.begin();  // motors coasting and LEDs off before anything else runs
    // Every motor PWM pin's timer, whichever it is (robot_profile.h lists them from the wiring):
    // one timer for both pins on the reference robot, two when the pins are wired to two timers.
    for (uint8_t i = 0; i < pins::FAST_PWM_PIN_COUNT; ++i) {
        rl::pwm_ultrasonic(pins::FAST_PWM_PINS[i]);
    }
    left_encoder.attach_external(left_encoder_edge);
    right_encoder.attach_external(right_encoder_edge);
    Serial.begin(115200);
    firmware.begin();
}

void loop() { firmware.poll(); }
