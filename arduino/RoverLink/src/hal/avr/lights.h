// Turn-signal / status LEDs: one pin per Lights bit. The core decides the pattern (blinking,
// hazard, brake lights); this only copies the mask to the pins.
#ifndef ROVERLINK_HAL_AVR_LIGHTS_H
#define ROVERLINK_HAL_AVR_LIGHTS_H

#if defined(ARDUINO_ARCH_AVR)

#include <stdint.h>

#include "motors.h"  // NO_PIN

namespace roverlink {
namespace avr {

class TurnSignalLeds {
public:
    // Pins in the order of the Lights bits; NO_PIN for an LED that is not fitted. LEDs are on
    // when the pin is high (anode on the pin through a resistor).
    constexpr TurnSignalLeds(uint8_t front_left, uint8_t front_right, uint8_t rear_left, uint8_t rear_right)
        : pins_{front_left, front_right, rear_left, rear_right} {}

    void begin();          // outputs, all off
    void set(uint8_t mask);  // Lights bits

private:
    static const uint8_t COUNT = 4;
    const uint8_t pins_[COUNT];
    uint8_t shown_ = 0;
};

// For boards without LEDs (DiffDriveBoard's default).
struct NoLights {
    void begin() {}
    void set(uint8_t) {}
};

}  // namespace avr
}  // namespace roverlink

#endif  // ARDUINO_ARCH_AVR
#endif  // ROVERLINK_HAL_AVR_LIGHTS_H
