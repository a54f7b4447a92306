#if defined(ARDUINO_ARCH_AVR)

#include "motors.h"

#include <Arduino.h>

namespace roverlink {
namespace avr {

uint8_t pwm_duty(int16_t effort_permille) {
    int16_t magnitude = effort_permille < 0 ? static_cast<int16_t>(-effort_permille) : effort_permille;
    if (magnitude > 1000 || magnitude < 0) {  // < 0: -INT16_MIN does not fit
        magnitude = 1000;
    }
    // 255 / 1000 = 51 / 200, so the product stays within 16 bits (1000 * 51 = 51000).
    return static_cast<uint8_t>((static_cast<uint16_t>(magnitude) * 51u + 100u) / 200u);
}

bool pwm_ultrasonic(uint8_t pin) {
    // Prescaler select bits are the low three of TCCRnB on every timer; 001 = clk/1.
    volatile uint8_t* control = nullptr;
    switch (digitalPinToTimer(pin)) {
#if defined(TCCR1B)
        case TIMER1A:
        case TIMER1B:
#if defined(TIMER1C)
        case TIMER1C:
#endif
            control = &TCCR1B;
            break;
#endif
#if defined(TCCR2B)
        case TIMER2A:
        case TIMER2B:
            control = &TCCR2B;
            break;
#endif
#if defined(TCCR3B)
        case TIMER3A:
        case TIMER3B:
        case TIMER3C:
            control = &TCCR3B;
            break;
#endif
#if defined(TCCR4B)
        case TIMER4A:
        case TIMER4B:
        case TIMER4C:
            control = &TCCR4B;
            break;
#endif
#if defined(TCCR5B)
        case TIMER5A:
        case TIMER5B:
        case TIMER5C:
            control = &TCCR5B;
            break;
#endif
        default:  // Timer0 (millis/micros) or not a PWM pin
            return false;
    }
    *control = static_cast<uint8_t>((*control & ~0x07u) | 0x01u);
    return true;
}

// -- TB6612FNG / L298N ---------------------------------------------------------------------------

void HBridgeMotor::begin() {
    pinMode(pwm_pin_, OUTPUT);
    pinMode(in1_pin_, OUTPUT);
    pinMode(in2_pin_, OUTPUT);
    drive(0, MotorMode::COAST);
}

void HBridgeMotor::drive(int16_t effort_permille, MotorMode mode) {
    switch (mode) {
        case MotorMode::DRIVE: {
            const bool forward = effort_permille >= 0;
            digitalWrite(in1_pin_, forward ? HIGH : LOW);
            digitalWrite(in2_pin_, forward ? LOW : HIGH);
            analogWrite(pwm_pin_, pwm_duty(effort_permille));
            break;
        }
        case MotorMode::BRAKE:
            digitalWrite(in1_pin_, HIGH);
            digitalWrite(in2_pin_, HIGH);
            digitalWrite(pwm_pin_, HIGH);
            break;
        case MotorMode::COAST:
        default:  // an unknown mode is treated as the gentlest safe state
            digitalWrite(pwm_pin_, LOW);
            digitalWrite(in1_pin_, LOW);
            digitalWrite(in2_pin_, LOW);
            break;
    }
}

void Tb6612Motor::begin() {
    HBridgeMotor::begin();  // inputs low first, so leaving standby cannot start the motor
    if (standby_pin_ != NO_PIN) {
        pinMode(standby_pin_, OUTPUT);
        digitalWrite(standby_pin_, HIGH);
    }
}

// -- BTS7960 -------------------------------------------------------------------------------------

void Bts7960Motor::begin() {
    pinMode(rpwm_pin_, OUTPUT);
    pinMode(lpwm_pin_, OUTPUT);
    pinMode(r_en_pin_, OUTPUT);
    pinMode(l_en_pin_, OUTPUT);
    drive(0, MotorMode::COAST);
}

void Bts7960Motor::enable(bool on) {
    digitalWrite(r_en_pin_, on ? HIGH : LOW);
    digitalWrite(l_en_pin_, on ? HIGH : LOW);
}

void Bts7960Motor::drive(int16_t effort_permille, MotorMode mode) {
    if (mode == MotorMode::DRIVE) {
        const uint8_t duty = pwm_duty(effort_permille);
        // The idle side goes low before the driven side is set, so a reversal passes through
        // brake rather than through both sides high.
        if (effort_permille >= 0) {
            analogWrite(lpwm_pin_, 0);
            enable(true);
            analogWrite(rpwm_pin_, duty);
        } else {
            analogWrite(rpwm_pin_, 0);
            enable(true);
            analogWrite(lpwm_pin_, duty);
        }
        return;
    }
    analogWrite(rpwm_pin_, 0);
    analogWrite(lpwm_pin_, 0);
    enable(mode == MotorMode::BRAKE);  // COAST (and anything unknown): enables low
}

}  // namespace avr
}  // namespace roverlink

#endif  // ARDUINO_ARCH_AVR
