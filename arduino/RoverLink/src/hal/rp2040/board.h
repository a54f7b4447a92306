// A robot on a Raspberry Pi Pico: every part the robot file wires (DC motors on TB6612, L298N or
// BTS7960 drivers, or an ESC and a steering servo; quadrature encoders; turn-signal LEDs) from one
// table of pins, which `roverlink firmware` generates into robot_profile.h as WIRING.
//
//   roverlink::rp2040::Rp2040Board board(robot_profile::WIRING);
//   extern "C" void isr_io_bank0() { board.on_pin_interrupt(); }
//   ...  board.begin();
//
// Motor PWM comes from the pins' slices at the driver's frequency (hardware.toml: 25 kHz for the
// TB6612, 1 kHz for the L298N and BTS7960), 5000 steps per period; ESC and servo pulses from their
// slice at 50 Hz in 1 us steps. Encoders count in the GPIO edge interrupt (every pin has one), with
// the same decoder as the AVR boards (hal/avr/quadrature.h). The Pico keeps no configuration:
// eeprom_read/eeprom_write report no storage, and the boot_id's noise is the ring oscillator's.
#ifndef ROVERLINK_HAL_RP2040_BOARD_H
#define ROVERLINK_HAL_RP2040_BOARD_H

#if defined(ROVERLINK_ARCH_RP2040)

#include <stdint.h>

#include "../avr/quadrature.h"
#include "../board.h"
#include "io.h"

namespace roverlink {
namespace rp2040 {

static const uint8_t NO_PIN = 0xFF;

enum class Driver : uint8_t {
    HBRIDGE = 0,  // TB6612 or L298N: pins pwm, in1, in2, standby (NO_PIN: none or tied high)
    BTS7960 = 1,  // pins rpwm, lpwm, r_en, l_en
};

struct MotorPins {
    Driver driver;
    uint8_t pins[4];
};

struct Wiring {
    uint8_t motor_count;  // 0 (ESC and servo) or one per wheel channel
    MotorPins motors[proto::WHEEL_COUNT];
    uint32_t motor_pwm_hz;
    uint8_t encoder_count;
    uint8_t encoders[proto::WHEEL_COUNT][2];  // a, b
    quadrature::Resolution resolution;
    uint8_t esc;       // NO_PIN: none
    uint8_t steering;  // NO_PIN: none
    uint8_t led_count;
    uint8_t leds[4];   // in Lights bit order
};

/// Interrupts off for the object's lifetime (PRIMASK saved and restored): a snapshot the encoder
/// interrupt cannot tear.
class InterruptsOff {
public:
    InterruptsOff() { __asm volatile("mrs %0, primask\n\tcpsid i" : "=r"(primask_)::"memory"); }
    ~InterruptsOff() { __asm volatile("msr primask, %0" ::"r"(primask_) : "memory"); }
    InterruptsOff(const InterruptsOff&) = delete;
    InterruptsOff& operator=(const InterruptsOff&) = delete;

private:
    uint32_t primask_;
};

class Rp2040Board : public Board {
public:
    static const uint32_t MOTOR_TOP = 4999;     // 5000 counts per period: 5 per permille
    static const uint32_t PULSE_TOP = 19999;    // 20 ms at 1 MHz
    static const uint32_t PULSE_DIVIDER = CLK_SYS_HZ / 1000000u;

    explicit Rp2040Board(const Wiring& wiring) : w_(wiring) {}

    /// Outputs safe (motors coasting, no pulses, LEDs off), encoders decoding from their levels,
    /// their edge interrupts on.
    void begin() {
        unreset(RESET_IO_BANK0 | RESET_PADS_BANK0 | RESET_PWM);
        const uint32_t divider = CLK_SYS_HZ / (w_.motor_pwm_hz * (MOTOR_TOP + 1u));
        for (uint8_t m = 0; m < w_.motor_count; ++m) {
            const MotorPins& p = w_.motors[m];
            const bool bts = p.driver == Driver::BTS7960;
            for (uint8_t i = 0; i < 4; ++i) {
                if (p.pins[i] == NO_PIN) {
                    continue;
                }
                if (i == 0 || (bts && i == 1)) {
                    Pwm::set(p.pins[i], 0);
                    Pwm::begin(p.pins[i], divider, MOTOR_TOP);
                } else {
                    output_pin(p.pins[i], false);
                }
            }
            drive(m, 0, MotorMode::COAST);
        }
        // The pulse slices start with their first width (pulse()): a compare value written to a
        // running slice takes effect at its next wrap, and the ESC would wait a period for it.
        const uint8_t pulse_pins[2] = {w_.esc, w_.steering};
        for (uint8_t pin : pulse_pins) {
            if (pin != NO_PIN) {
                output_pin(pin, false);
            }
        }
        for (uint8_t i = 0; i < w_.led_count; ++i) {
            output_pin(w_.leds[i], false);
        }
        for (uint8_t e = 0; e < w_.encoder_count; ++e) {
            input_pin(w_.encoders[e][0], true);
            input_pin(w_.encoders[e][1], true);
            decoders_[e].reset(w_.resolution, levels(e));
            pin_edges(w_.encoders[e][0]);
            pin_edges(w_.encoders[e][1]);
        }
        if (w_.encoder_count) {
            enable_irq(IRQ_IO_BANK0);
        }
    }

    /// From isr_io_bank0: every encoder whose pins saw an edge decodes its present levels.
    void on_pin_interrupt() {
        for (uint8_t e = 0; e < w_.encoder_count; ++e) {
            if (take_edges(w_.encoders[e][0]) | take_edges(w_.encoders[e][1])) {
                decoders_[e].update(levels(e));
            }
        }
    }

    void read_encoders(int32_t counts[proto::WHEEL_COUNT]) override {
        InterruptsOff off;  // every wheel in one snapshot
        for (uint8_t w = 0; w < proto::WHEEL_COUNT; ++w) {
            counts[w] = w < w_.encoder_count ? decoders_[w].count : 0;
        }
    }

    void zero_encoders() override {
        InterruptsOff off;
        for (uint8_t e = 0; e < w_.encoder_count; ++e) {
            decoders_[e].count = 0;
        }
    }

    void drive(uint8_t wheel, int16_t effort_permille, MotorMode mode) override {
        if (wheel >= w_.motor_count) {
            return;
        }
        const MotorPins& p = w_.motors[wheel];
        const uint32_t level = duty(effort_permille);
        const bool forward = effort_permille >= 0;
        if (p.driver == Driver::BTS7960) {
            // The idle side low before the driven one, so a reversal passes through brake.
            Pwm::set(p.pins[forward ? 1 : 0], 0);
            const bool drive_on = mode == MotorMode::DRIVE;
            Pwm::set(p.pins[forward ? 0 : 1], drive_on ? level : 0);
            const bool enabled = drive_on || mode == MotorMode::BRAKE;
            write_pin(p.pins[2], enabled);
            write_pin(p.pins[3], enabled);
            return;
        }
        switch (mode) {
            case MotorMode::DRIVE:
                write_pin(p.pins[1], forward);
                write_pin(p.pins[2], !forward);
                Pwm::set(p.pins[0], level);
                break;
            case MotorMode::BRAKE:
                write_pin(p.pins[1], true);
                write_pin(p.pins[2], true);
                Pwm::set(p.pins[0], MOTOR_TOP + 1u);
                break;
            case MotorMode::COAST:
            default:  // an unknown mode: the gentlest safe state
                Pwm::set(p.pins[0], 0);
                write_pin(p.pins[1], false);
                write_pin(p.pins[2], false);
                break;
        }
        if (p.pins[3] != NO_PIN) {
            write_pin(p.pins[3], true);  // STBY high: the safe states go through IN1/IN2
        }
    }

    void esc_pulse(uint16_t pulse_us) override { pulse(w_.esc, pulse_us); }
    void steering_pulse(uint16_t pulse_us) override { pulse(w_.steering, pulse_us); }

    void lights(uint8_t mask) override {
        for (uint8_t i = 0; i < w_.led_count; ++i) {
            write_pin(w_.leds[i], (mask >> i) & 1u);
        }
    }

    uint32_t micros() override { return rp2040::micros(); }

    // No configuration storage on the Pico (docs/firmware.md): the core sees no EEPROM.
    bool eeprom_read(uint16_t, uint8_t*, uint16_t) override { return false; }
    bool eeprom_write(uint16_t, const uint8_t*, uint16_t) override { return false; }

    uint32_t entropy() override { return noise_bits(32); }

    /// Invalid transitions (missed edges) of encoder `e` since begin().
    uint16_t encoder_errors(uint8_t e) const { return e < w_.encoder_count ? decoders_[e].errors : 0; }

    /// PWM counts per period high for an effort: |effort| clamped to 1000, 5 counts per permille.
    static uint32_t duty(int16_t effort_permille) {
        int32_t magnitude = effort_permille < 0 ? -static_cast<int32_t>(effort_permille) : effort_permille;
        if (magnitude > 1000) {
            magnitude = 1000;
        }
        return static_cast<uint32_t>(magnitude) * ((MOTOR_TOP + 1u) / 1000u);
    }

private:
    static void output_pin(uint8_t pin, bool high) {
        write_pin(pin, high);
        pin_function(pin, GPIO_FUNC_SIO);
        reg(SIO_GPIO_OE_SET) = 1u << pin;
    }

    static void write_pin(uint8_t pin, bool high) {
        if (pin != NO_PIN) {
            reg(high ? SIO_GPIO_OUT_SET : SIO_GPIO_OUT_CLR) = 1u << pin;
        }
    }

    static void pulse(uint8_t pin, uint16_t pulse_us) {
        if (pin == NO_PIN) {
            return;
        }
        // 0 stops the pulses (the pin held low: a floating signal wire can look like pulses to an
        // ESC); a width is clamped to what SET_CONFIG allows a servo.
        if (pulse_us != 0 && pulse_us < proto::SetConfig::SERVO_MIN_US_MIN) {
            pulse_us = proto::SetConfig::SERVO_MIN_US_MIN;
        }
        if (pulse_us > proto::SetConfig::SERVO_MAX_US_MAX) {
            pulse_us = proto::SetConfig::SERVO_MAX_US_MAX;
        }
        Pwm::set(pin, pulse_us);  // the compare register is latched at the wrap: whole pulses only
        if (!(reg(pwm_csr(Pwm::slice(pin))) & 1u)) {
            Pwm::begin(pin, PULSE_DIVIDER, PULSE_TOP);  // the first pulse starts now
        } else if ((reg(gpio_ctrl(pin)) & 0x1fu) != GPIO_FUNC_PWM) {
            pin_function(pin, GPIO_FUNC_PWM);  // the slice runs for its other channel already
        }
    }

    uint8_t levels(uint8_t e) const {
        return static_cast<uint8_t>((pin_level(w_.encoders[e][0]) ? 2u : 0u) | (pin_level(w_.encoders[e][1]) ? 1u : 0u));
    }

    const Wiring& w_;
    quadrature::Decoder decoders_[proto::WHEEL_COUNT] = {};
};

}  // namespace rp2040
}  // namespace roverlink

#endif  // ROVERLINK_ARCH_RP2040
#endif  // ROVERLINK_HAL_RP2040_BOARD_H
