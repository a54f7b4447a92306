// A quadrature encoder counted in pin interrupts.
//
// The sketch owns the interrupt vectors (so this library never claims one a user needs elsewhere)
// and calls on_edge() from them:
//
//   roverlink::avr::QuadratureEncoder left_encoder(2, 3);     // Uno/Mega external interrupt pins
//   void left_edge() { left_encoder.on_edge(); }
//   ...  left_encoder.begin(); left_encoder.attach_external(left_edge);
//
//   roverlink::avr::QuadratureEncoder right_encoder(A8, A9);  // Mega pin-change pins (PCINT16/17)
//   ISR(PCINT2_vect) { right_encoder.on_edge(); }
//   ...  right_encoder.begin(); right_encoder.enable_pin_change();
//
// Both channels must interrupt (any change) in every resolution: see quadrature.h.
#ifndef ROVERLINK_HAL_AVR_ENCODER_H
#define ROVERLINK_HAL_AVR_ENCODER_H

#if defined(ARDUINO_ARCH_AVR)

#include <Arduino.h>
#include <util/atomic.h>

#include "mcu.h"
#include "quadrature.h"

namespace roverlink {
namespace avr {

class QuadratureEncoder {
public:
    // constexpr: the sketch's global encoders (and boards) are initialised at link time, with no
    // constructor code to run and, for boards, no base-class vtable kept in SRAM.
    constexpr QuadratureEncoder(uint8_t pin_a, uint8_t pin_b,
                                quadrature::Resolution resolution = quadrature::Resolution::X4, bool pullups = true)
        : pin_a_(pin_a),
          pin_b_(pin_b),
          resolution_(resolution),
          pullups_(pullups),
          decoder_{0, 0, 0, quadrature::table_for(resolution)} {}

    // Pins as inputs (open-collector encoders need the pull-ups), decoding from the present levels.
    void begin() {
        pin_input(pin_a_, pullups_);
        pin_input(pin_b_, pullups_);
        a_in_ = portInputRegister(digitalPinToPort(pin_a_));
        b_in_ = portInputRegister(digitalPinToPort(pin_b_));
        a_mask_ = digitalPinToBitMask(pin_a_);
        b_mask_ = digitalPinToBitMask(pin_b_);
        ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { decoder_.reset(resolution_, levels()); }
    }

    // Both pins on external interrupts (INTn, any change) calling `handler`, which calls on_edge().
    // False when a pin has no external interrupt (use pin-change interrupts for it).
    bool attach_external(void (*handler)()) {
        const int a = digitalPinToInterrupt(pin_a_), b = digitalPinToInterrupt(pin_b_);
        if (a == NOT_AN_INTERRUPT || b == NOT_AN_INTERRUPT) {
            return false;
        }
        attachInterrupt(a, handler, CHANGE);
        attachInterrupt(b, handler, CHANGE);
        return true;
    }

    // Both pins in their port's pin-change mask; the sketch's ISR(PCINTn_vect) calls on_edge().
    // False when a pin has no pin-change interrupt.
    bool enable_pin_change() { return enable_pin_change(pin_a_) && enable_pin_change(pin_b_); }

    // From the pin interrupts only (interrupts are off there). Reads the port registers
    // directly: digitalRead() would cost several microseconds per edge.
    void on_edge() { decoder_.update(levels()); }

    // Shared with the interrupt: call these with interrupts off, as the board's read_encoders()
    // does for all wheels at once so the counts form one snapshot.
    int32_t count_unlocked() const { return decoder_.count; }
    void zero_unlocked() { decoder_.count = 0; }

    // Invalid transitions (missed edges) since begin(); saturates at 65535.
    uint16_t errors() {
        uint16_t e;
        ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { e = decoder_.errors; }
        return e;
    }

    uint8_t pin_a() const { return pin_a_; }
    uint8_t pin_b() const { return pin_b_; }

private:
    uint8_t levels() const {
        return static_cast<uint8_t>(((*a_in_ & a_mask_) ? 2u : 0u) | ((*b_in_ & b_mask_) ? 1u : 0u));
    }

    static bool enable_pin_change(uint8_t pin_number) {
        const int pin = pin_number;  // the variant's macros compare with >= 0: an unsigned pin warns
        volatile uint8_t* pcicr = digitalPinToPCICR(pin);
        if (pcicr == nullptr) {
            return false;
        }
        ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
            *digitalPinToPCMSK(pin) |= static_cast<uint8_t>(1u << digitalPinToPCMSKbit(pin));
            PCIFR = static_cast<uint8_t>(1u << digitalPinToPCICRbit(pin));  // drop an edge seen before
            *pcicr |= static_cast<uint8_t>(1u << digitalPinToPCICRbit(pin));
        }
        return true;
    }

    const uint8_t pin_a_;
    const uint8_t pin_b_;
    const quadrature::Resolution resolution_;
    const bool pullups_;
    quadrature::Decoder decoder_;
    volatile uint8_t* a_in_ = nullptr;  // PINx registers and bit masks, from begin()
    volatile uint8_t* b_in_ = nullptr;
    uint8_t a_mask_ = 0;
    uint8_t b_mask_ = 0;
};

}  // namespace avr
}  // namespace roverlink

#endif  // ARDUINO_ARCH_AVR
#endif  // ROVERLINK_HAL_AVR_ENCODER_H
