#if defined(ARDUINO_ARCH_AVR)

#include "lights.h"

#include <Arduino.h>

namespace roverlink {
namespace avr {

static_assert(Lights::FRONT_LEFT == 1 && Lights::FRONT_RIGHT == 2 && Lights::REAR_LEFT == 4 && Lights::REAR_RIGHT == 8,
              "TurnSignalLeds keeps its pins in the order of the Lights bits");

void TurnSignalLeds::begin() {
    for (uint8_t i = 0; i < COUNT; ++i) {
        if (pins_[i] != NO_PIN) {
            digitalWrite(pins_[i], LOW);
            pinMode(pins_[i], OUTPUT);
        }
    }
    shown_ = 0;
}

void TurnSignalLeds::set(uint8_t mask) {
    // Only changed pins are written: the core may set the mask every tick, and digitalWrite()
    // is a few microseconds each.
    const uint8_t changed = static_cast<uint8_t>(mask ^ shown_);
    for (uint8_t i = 0; i < COUNT; ++i) {
        const uint8_t bit = static_cast<uint8_t>(1u << i);
        if ((changed & bit) != 0 && pins_[i] != NO_PIN) {
            digitalWrite(pins_[i], (mask & bit) != 0 ? HIGH : LOW);
        }
    }
    shown_ = mask;
}

}  // namespace avr
}  // namespace roverlink

#endif  // ARDUINO_ARCH_AVR
