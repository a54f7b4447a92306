// A differential-drive robot: two DC motors of one driver type, two quadrature encoders and
// optional turn-signal LEDs. Wheel 0 is the left wheel, wheel 1 the right one.
//
//   roverlink::avr::Tb6612Motor left_motor(6, 22, 23, 26), right_motor(7, 24, 25, 26);
//   roverlink::avr::QuadratureEncoder left_encoder(2, 3), right_encoder(18, 19);
//   roverlink::avr::TurnSignalLeds leds(30, 31, 32, 33);
//   roverlink::avr::DiffDriveBoard<roverlink::avr::Tb6612Motor, roverlink::avr::TurnSignalLeds>
//       board(left_motor, right_motor, left_encoder, right_encoder, leds, A0);
//
// The parts are the sketch's own objects (the encoders must be reachable from its interrupt
// handlers); the board only holds references to them. The sketch calls board.begin() before
// firmware.begin(), then enables the encoder interrupts.
#ifndef ROVERLINK_HAL_AVR_DIFF_DRIVE_BOARD_H
#define ROVERLINK_HAL_AVR_DIFF_DRIVE_BOARD_H

#if defined(ARDUINO_ARCH_AVR)

#include <util/atomic.h>

#include <Arduino.h>

#include "../board.h"
#include "encoder.h"
#include "lights.h"
#include "mcu.h"

namespace roverlink {
namespace avr {

template <class Motor, class Leds = NoLights>
class DiffDriveBoard : public Board {
public:
    static_assert(proto::WHEEL_COUNT == 2, "a differential drive has two wheel channels");

    constexpr DiffDriveBoard(Motor& left_motor, Motor& right_motor, QuadratureEncoder& left_encoder,
                   QuadratureEncoder& right_encoder, Leds& leds, uint8_t entropy_pin)
        : motors_{&left_motor, &right_motor},
          encoders_{&left_encoder, &right_encoder},
          leds_(leds),
          entropy_pin_(entropy_pin) {}

    // Outputs safe (coasting, LEDs off), encoder pins read. Interrupts are the sketch's to enable.
    void begin() {
        for (uint8_t w = 0; w < WHEELS; ++w) {
            motors_[w]->begin();
            encoders_[w]->begin();
        }
        leds_.begin();
    }

    void read_encoders(int32_t counts[proto::WHEEL_COUNT]) override {
        // Both wheels in one critical section: one snapshot, no torn 32-bit value.
        ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
            counts[0] = encoders_[0]->count_unlocked();
            counts[1] = encoders_[1]->count_unlocked();
        }
    }

    void zero_encoders() override {
        ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
            encoders_[0]->zero_unlocked();
            encoders_[1]->zero_unlocked();
        }
    }

    void drive(uint8_t wheel, int16_t effort_permille, MotorMode mode) override {
        if (wheel < WHEELS) {
            motors_[wheel]->drive(effort_permille, mode);
        }
    }

    void lights(uint8_t mask) override { leds_.set(mask); }

    // No ESC or steering servo on a differential drive.
    void esc_pulse(uint16_t) override {}
    void steering_pulse(uint16_t) override {}

    uint32_t micros() override { return ::micros(); }
    bool eeprom_read(uint16_t address, uint8_t* data, uint16_t length) override {
        return avr::eeprom_read(address, data, length);
    }
    bool eeprom_write(uint16_t address, const uint8_t* data, uint16_t length) override {
        return avr::eeprom_write(address, data, length);
    }
    uint32_t entropy() override { return adc_entropy(entropy_pin_); }

private:
    static const uint8_t WHEELS = 2;  // left and right: this board's own, whatever the protocol carries
    Motor* const motors_[WHEELS];
    QuadratureEncoder* const encoders_[WHEELS];
    Leds& leds_;
    const uint8_t entropy_pin_;  // an analog input with nothing connected
};

}  // namespace avr
}  // namespace roverlink

#endif  // ARDUINO_ARCH_AVR
#endif  // ROVERLINK_HAL_AVR_DIFF_DRIVE_BOARD_H
