// DC motor drivers: TB6612FNG, L298N and BTS7960 (IBT-2), one object per motor.
//
// Each takes the core's signed effort in permille (already corrected for motor_invert) and a
// MotorMode, and puts its pins in the state docs/control.md section 5 gives for that driver.
// PWM goes through analogWrite(), so the PWM pins must be hardware PWM pins whose timer nobody
// reprograms: not the servo pulse timer (rc_pulses.h) and not Timer0 (millis/micros) if you
// change its frequency with pwm_ultrasonic(). Which driver needs which frequency, and which timer
// each pin is on: protocol/spec/hardware.toml (a robot file's build sets every pin's timer).
#ifndef ROVERLINK_HAL_AVR_MOTORS_H
#define ROVERLINK_HAL_AVR_MOTORS_H

#if defined(ARDUINO_ARCH_AVR)

#include <stdint.h>

#include "../board.h"

namespace roverlink {
namespace avr {

static const uint8_t NO_PIN = 0xFF;

// analogWrite() duty (0..255) for an effort in permille: |effort| clamped to 1000, rounded.
uint8_t pwm_duty(int16_t effort_permille);

// Raises the PWM frequency of the timer behind `pin` to 31.4 kHz (prescaler 1 in the 8-bit
// phase-correct mode the Arduino core sets up), above hearing: motors stop whining. Not for
// Timer0 pins (that would break millis/micros): returns false for them and for non-PWM pins.
bool pwm_ultrasonic(uint8_t pin);

// TB6612FNG or L298N channel: PWM on PWMx / ENx, direction on IN1/IN2.
//   DRIVE: IN1/IN2 = H/L forward or L/H reverse, PWM duty |effort|
//   COAST: IN1 = IN2 = L, PWM low (outputs off on both chips)
//   BRAKE: IN1 = IN2 = H, PWM high (short brake; the L298N brakes only while EN is high, the
//          TB6612 brakes with either PWM level)
class HBridgeMotor {
public:
    constexpr HBridgeMotor(uint8_t pwm_pin, uint8_t in1_pin, uint8_t in2_pin)
        : pwm_pin_(pwm_pin), in1_pin_(in1_pin), in2_pin_(in2_pin) {}

    void begin();  // outputs, coasting
    void drive(int16_t effort_permille, MotorMode mode);

private:
    const uint8_t pwm_pin_;
    const uint8_t in1_pin_;
    const uint8_t in2_pin_;
};

// L298N: ENA/ENB is the PWM pin (remove the 5 V jumper on it).
typedef HBridgeMotor L298nMotor;

// TB6612FNG channel. STBY (shared by both channels of a chip; NO_PIN when tied to VCC) is held
// high from begin(): the safe states are reached through IN1/IN2, which keeps BRAKE possible.
class Tb6612Motor : public HBridgeMotor {
public:
    constexpr Tb6612Motor(uint8_t pwm_pin, uint8_t in1_pin, uint8_t in2_pin, uint8_t standby_pin = NO_PIN)
        : HBridgeMotor(pwm_pin, in1_pin, in2_pin), standby_pin_(standby_pin) {}

    void begin();

private:
    const uint8_t standby_pin_;
};

// BTS7960 half-bridge pair (IBT-2 board): RPWM drives forward, LPWM reverse, R_EN/L_EN enable.
//   DRIVE: enables high, the other PWM 0
//   COAST: both PWM 0, enables low (both half-bridges off: free-wheel)
//   BRAKE: both PWM 0, enables high (both low sides on: brake)
// R_EN and L_EN may share one pin (pass it twice).
class Bts7960Motor {
public:
    constexpr Bts7960Motor(uint8_t rpwm_pin, uint8_t lpwm_pin, uint8_t r_en_pin, uint8_t l_en_pin)
        : rpwm_pin_(rpwm_pin), lpwm_pin_(lpwm_pin), r_en_pin_(r_en_pin), l_en_pin_(l_en_pin) {}

    void begin();  // outputs, coasting
    void drive(int16_t effort_permille, MotorMode mode);

private:
    void enable(bool on);

    const uint8_t rpwm_pin_;
    const uint8_t lpwm_pin_;
    const uint8_t r_en_pin_;
    const uint8_t l_en_pin_;
};

}  // namespace avr
}  // namespace roverlink

#endif  // ARDUINO_ARCH_AVR
#endif  // ROVERLINK_HAL_AVR_MOTORS_H
