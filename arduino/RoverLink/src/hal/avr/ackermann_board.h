// An Ackermann car: drive motor behind an RC ESC, a steering servo, and one encoder on the
// motor (wheel channel 0; channel 1 reads 0). ESC and servo pulses come from one 16-bit timer
// (rc_pulses.h), Timer1 by default: pins 9 and 10 on the Uno.
//
//   roverlink::avr::QuadratureEncoder motor_encoder(2, 3);
//   roverlink::avr::AckermannBoard<> board(motor_encoder, roverlink::avr::PulseChannel::A,
//                                          roverlink::avr::PulseChannel::B, A0);
#ifndef ROVERLINK_HAL_AVR_ACKERMANN_BOARD_H
#define ROVERLINK_HAL_AVR_ACKERMANN_BOARD_H

#if defined(ARDUINO_ARCH_AVR)

#include <util/atomic.h>

#include <Arduino.h>

#include "../board.h"
#include "encoder.h"
#include "mcu.h"
#include "rc_pulses.h"

namespace roverlink {
namespace avr {

template <class Timer = Timer1>
class AckermannBoard : public Board {
public:
    constexpr AckermannBoard(QuadratureEncoder& encoder, PulseChannel esc, PulseChannel steering, uint8_t entropy_pin)
        : encoder_(encoder), esc_(esc), steering_(steering), entropy_pin_(entropy_pin) {}

    // Timer taken over, both signal pins held low (no pulses until the core asks), encoder pins
    // read. The core sends ESC neutral from its begin(): the ESC's arming window starts there.
    void begin() {
        PulseTimer<Timer>::begin();
        PulseTimer<Timer>::write(esc_, 0);
        PulseTimer<Timer>::write(steering_, 0);
        encoder_.begin();
    }

    void read_encoders(int32_t counts[proto::WHEEL_COUNT]) override {
        ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { counts[0] = encoder_.count_unlocked(); }
        for (uint8_t w = 1; w < proto::WHEEL_COUNT; ++w) {
            counts[w] = 0;
        }
    }

    void zero_encoders() override {
        ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { encoder_.zero_unlocked(); }
    }

    void esc_pulse(uint16_t pulse_us) override { PulseTimer<Timer>::write(esc_, pulse_us); }
    void steering_pulse(uint16_t pulse_us) override { PulseTimer<Timer>::write(steering_, pulse_us); }

    // The drive motor is behind the ESC (esc_pulse), and there are no LEDs.
    void drive(uint8_t, int16_t, MotorMode) override {}
    void lights(uint8_t) override {}

    uint32_t micros() override { return ::micros(); }
    bool eeprom_read(uint16_t address, uint8_t* data, uint16_t length) override {
        return avr::eeprom_read(address, data, length);
    }
    bool eeprom_write(uint16_t address, const uint8_t* data, uint16_t length) override {
        return avr::eeprom_write(address, data, length);
    }
    uint32_t entropy() override { return adc_entropy(entropy_pin_); }

    uint8_t esc_pin() const { return PulseTimer<Timer>::pin(esc_); }
    uint8_t steering_pin() const { return PulseTimer<Timer>::pin(steering_); }

private:
    QuadratureEncoder& encoder_;
    const PulseChannel esc_;
    const PulseChannel steering_;
    const uint8_t entropy_pin_;  // an analog input with nothing connected
};

}  // namespace avr
}  // namespace roverlink

#endif  // ARDUINO_ARCH_AVR
#endif  // ROVERLINK_HAL_AVR_ACKERMANN_BOARD_H
