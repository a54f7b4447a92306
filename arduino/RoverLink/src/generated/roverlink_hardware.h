// DO NOT EDIT: generated from protocol/spec/hardware.toml by `python -m protocol generate`.
// The hardware contract: what the portable core hands to a Board (hal/board.h). Not on the wire.
#ifndef ROVERLINK_GENERATED_HARDWARE_H
#define ROVERLINK_GENERATED_HARDWARE_H

#include <stdint.h>

namespace roverlink {

// How a DC motor driver holds a wheel.
enum class MotorMode : uint8_t {
    DRIVE = 0,  // PWM duty |effort| / 1000 in the effort's direction.
    COAST = 1,  // Outputs off: no current flows, the wheel turns freely.
    BRAKE = 2,  // Terminals shorted, back-EMF brakes (TB6612/L298N: both inputs high; BTS7960: both PWM 0, enables high).
};
inline bool is_valid_MotorMode(uint8_t value) {
    return value <= 2;
}

// Turn-signal / status lights, one bit each (the patterns: docs/firmware.md, Lights).
struct Lights {
    enum : uint8_t {
        FRONT_LEFT = 0x1,  // Front left LED.
        FRONT_RIGHT = 0x2,  // Front right LED.
        REAR_LEFT = 0x4,  // Rear left LED.
        REAR_RIGHT = 0x8,  // Rear right LED.
    };
    static const uint8_t MASK = 0xF;
};

}  // namespace roverlink

#endif  // ROVERLINK_GENERATED_HARDWARE_H
