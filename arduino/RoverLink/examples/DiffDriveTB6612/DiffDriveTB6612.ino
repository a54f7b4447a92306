// DiffDriveTB6612: the ros_arduino_bridge-style car on an Arduino Mega 2560.
//
// Two DC gearmotors on a TB6612FNG, two quadrature encoders (x4, on the external interrupt pins),
// four turn-signal LEDs, stream feedback. Defaults (64 mm wheels, 1560 counts/rev, PID gains...)
// are in robot_profile.h, generated from protocol/spec/robots.toml; change them over the link.
// Wiring, timers and flashing: docs/firmware.md, "Boards, wiring and flashing".
//
// Using an L298N instead: replace Tb6612Motor by L298nMotor, wire ENA/ENB to the PWM pins below
// (jumpers off) and IN1..IN4 to the direction pins, and drop the STBY argument.
#include <RoverLink.h>

#include "robot_profile.h"

namespace rl = roverlink::avr;

// TB6612FNG. Both PWM pins are on Timer4, which is sped up to 31.4 kHz below (no motor whine).
const uint8_t LEFT_PWM = 6;    // PWMA, Timer4 OC4A
const uint8_t LEFT_IN1 = 22;   // AIN1
const uint8_t LEFT_IN2 = 23;   // AIN2
const uint8_t RIGHT_PWM = 7;   // PWMB, Timer4 OC4B
const uint8_t RIGHT_IN1 = 24;  // BIN1
const uint8_t RIGHT_IN2 = 25;  // BIN2
const uint8_t STANDBY = 26;    // STBY, shared by both channels

// Encoders: all four channels on external interrupts (INT4, INT5, INT3, INT2).
const uint8_t LEFT_ENC_A = 2;
const uint8_t LEFT_ENC_B = 3;
const uint8_t RIGHT_ENC_A = 18;
const uint8_t RIGHT_ENC_B = 19;
static_assert(digitalPinToInterrupt(LEFT_ENC_A) != NOT_AN_INTERRUPT &&
                  digitalPinToInterrupt(LEFT_ENC_B) != NOT_AN_INTERRUPT &&
                  digitalPinToInterrupt(RIGHT_ENC_A) != NOT_AN_INTERRUPT &&
                  digitalPinToInterrupt(RIGHT_ENC_B) != NOT_AN_INTERRUPT,
              "encoder pins must be external interrupt pins (Mega 2560: 2, 3, 18, 19, 20, 21)");

// Turn-signal LEDs (through 330 ohm resistors to GND).
const uint8_t LED_FRONT_LEFT = 30;
const uint8_t LED_FRONT_RIGHT = 31;
const uint8_t LED_REAR_LEFT = 32;
const uint8_t LED_REAR_RIGHT = 33;

const uint8_t UNCONNECTED_ANALOG = A0;  // noise for the per-boot random boot_id: leave it open

rl::Tb6612Motor left_motor(LEFT_PWM, LEFT_IN1, LEFT_IN2, STANDBY);
rl::Tb6612Motor right_motor(RIGHT_PWM, RIGHT_IN1, RIGHT_IN2, STANDBY);
rl::QuadratureEncoder left_encoder(LEFT_ENC_A, LEFT_ENC_B);
rl::QuadratureEncoder right_encoder(RIGHT_ENC_A, RIGHT_ENC_B);
rl::TurnSignalLeds leds(LED_FRONT_LEFT, LED_FRONT_RIGHT, LED_REAR_LEFT, LED_REAR_RIGHT);
rl::DiffDriveBoard<rl::Tb6612Motor, rl::TurnSignalLeds> board(left_motor, right_motor, left_encoder, right_encoder,
                                                              leds, UNCONNECTED_ANALOG);

static const roverlink::Robot ROBOT = {robot_profile::NAME,          robot_profile::BOARD,
                                       robot_profile::CAPABILITIES,  robot_profile::FEEDBACK_MODE,
                                       robot_profile::default_config, robot_profile::default_pid};
roverlink::Firmware firmware(Serial, board, ROBOT);

void left_encoder_edge() { left_encoder.on_edge(); }
void right_encoder_edge() { right_encoder.on_edge(); }

void setup() {
    board.begin();  // motors coasting and LEDs off before anything else runs
    rl::pwm_ultrasonic(LEFT_PWM);  // Timer4: both motor PWM pins
    left_encoder.attach_external(left_encoder_edge);
    right_encoder.attach_external(right_encoder_edge);
    Serial.begin(115200);
    firmware.begin();
}

void loop() { firmware.poll(); }
