// The hardware layer's contract: what the portable core needs from a board.
//
// The core (src/core/) owns every decision (session, PID, limits, pulse widths, LED patterns); a
// Board only moves pins. AVR boards implement it in src/hal/avr/, the native build in
// src/hal/native/, so the same core runs on an Uno, a Mega 2560 and under g++ in tests.
#ifndef ROVERLINK_HAL_BOARD_H
#define ROVERLINK_HAL_BOARD_H

#include <stddef.h>
#include <stdint.h>

#include "../generated/roverlink_hardware.h"
#include "../generated/roverlink_protocol.h"

namespace roverlink {

// MotorMode (how a DC motor driver holds a wheel) and the Lights bits come from the hardware
// contract, protocol/spec/hardware.toml, which the emulator and the native tests share.

class Board {
public:
    // Microseconds since boot; wraps every 71.6 minutes (callers use unsigned differences).
    virtual uint32_t micros() = 0;

    // Cumulative encoder counts per wheel, copied atomically (interrupts off for the copy), raw:
    // before the config's encoder_invert. Wheels without an encoder read 0.
    virtual void read_encoders(int32_t counts[proto::WHEEL_COUNT]) = 0;
    virtual void zero_encoders() = 0;

    // DC motor of `wheel`: signed effort in permille (-1000..1000) when mode is DRIVE, already
    // corrected for the config's motor_invert. A board without that motor ignores the call.
    virtual void drive(uint8_t wheel, int16_t effort_permille, MotorMode mode) = 0;

    // RC pulse widths (microseconds, 0 = no pulses) for an ESC and a steering servo.
    virtual void esc_pulse(uint16_t pulse_us) = 0;
    virtual void steering_pulse(uint16_t pulse_us) = 0;

    virtual void lights(uint8_t mask) = 0;  // Lights bits; a board without LEDs ignores it

    // Non-volatile storage; false when the address range does not exist or a write fails.
    virtual bool eeprom_read(uint16_t address, uint8_t* data, uint16_t length) = 0;
    virtual bool eeprom_write(uint16_t address, const uint8_t* data, uint16_t length) = 0;

    // A few bits of physical noise (ADC, timer jitter) for the per-boot random boot_id.
    virtual uint32_t entropy() = 0;

protected:
    ~Board() {}  // never deleted through this interface (no heap on the firmware)
};

}  // namespace roverlink

#endif  // ROVERLINK_HAL_BOARD_H
