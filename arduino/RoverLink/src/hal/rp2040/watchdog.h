// The RP2040's watchdog (datasheet 4.7): a firmware that stops feeding it (a hang, an interrupt
// storm) is reset, cores and peripherals, the clocks' oscillators excepted; the board boots again
// with a new boot_id and its outputs in the reset state (motors released).
#ifndef ROVERLINK_HAL_RP2040_WATCHDOG_H
#define ROVERLINK_HAL_RP2040_WATCHDOG_H

#if defined(ROVERLINK_ARCH_RP2040)

#include <stdint.h>

#include "regs.h"

namespace roverlink {
namespace rp2040 {

class Watchdog {
public:
    /// Resets the chip `ms` after the last feed() once begun (at most 8388 ms).
    explicit constexpr Watchdog(uint32_t ms) : load_(ms * 2000u) {}

    /// Armed; needs clocks_begin()'s 1 MHz tick.
    void begin() const {
        reg(PSM_WDSEL) = 0x1ffffu & ~((1u << 0) | (1u << 1));  // everything but ROSC and XOSC
        feed();
        set_bits(WATCHDOG_CTRL, WATCHDOG_CTRL_ENABLE);
    }
    void feed() const { reg(WATCHDOG_LOAD) = load_; }
    /// Whether the last reset was the watchdog's (its timer running out, or a forced trigger).
    static bool caused_reset() { return (reg(WATCHDOG_REASON) & 3u) != 0; }

private:
    const uint32_t load_;  // the counter goes down twice per tick (erratum RP2040-E1): 2 per us
};

}  // namespace rp2040
}  // namespace roverlink

#endif  // ROVERLINK_ARCH_RP2040
#endif  // ROVERLINK_HAL_RP2040_WATCHDOG_H
