// The RP2040's clocks as the firmware runs them (datasheet 2.15-2.18): the Pico's 12 MHz crystal,
// PLL_SYS at 1500 MHz / 6 / 2 = 125 MHz for clk_sys and clk_peri, clk_ref from the crystal, and the
// watchdog's tick at 1 MHz, which also clocks the microsecond timer. Out of reset the chip runs
// from its ring oscillator (a few MHz, not accurate enough for a UART at 115200 baud).
#ifndef ROVERLINK_HAL_RP2040_CLOCKS_H
#define ROVERLINK_HAL_RP2040_CLOCKS_H

#if defined(ROVERLINK_ARCH_RP2040)

#include "io.h"
#include "regs.h"

namespace roverlink {
namespace rp2040 {

inline void clocks_begin() {
    // The crystal: 1..15 MHz range, ~1 ms start-up (datasheet 2.16.3: delay in units of 256 cycles).
    reg(XOSC_STARTUP) = (XOSC_HZ / 1000u + 128u) / 256u;
    reg(XOSC_CTRL) = (0xfabu << 12) | 0xaa0u;
    while (!(reg(XOSC_STATUS) & (1u << 31))) {
    }
    // clk_sys and clk_ref onto glitch-free sources before the PLL changes under them.
    clear_bits(CLK_SYS_CTRL, 1u);  // clk_sys = clk_ref
    while (reg(CLK_SYS_SELECTED) != 1u) {
    }
    reg(CLK_REF_CTRL) = 2u;  // clk_ref = XOSC
    while (reg(CLK_REF_SELECTED) != (1u << 2)) {
    }
    // PLL_SYS: REFDIV 1, VCO = 12 MHz * 125 = 1500 MHz, POSTDIV1 6, POSTDIV2 2 (datasheet 2.18.2).
    set_bits(RESETS_RESET, RESET_PLL_SYS);
    unreset(RESET_PLL_SYS);
    reg(PLL_CS) = 1u;
    reg(PLL_FBDIV_INT) = 125u;
    clear_bits(PLL_PWR, (1u << 0) | (1u << 5));  // PD, VCOPD
    while (!(reg(PLL_CS) & (1u << 31))) {        // LOCK
    }
    reg(PLL_PRIM) = (6u << 16) | (2u << 12);
    clear_bits(PLL_PWR, 1u << 3);  // POSTDIVPD
    reg(CLK_SYS_CTRL) = 0u << 5;   // AUXSRC = PLL_SYS, still on clk_ref
    set_bits(CLK_SYS_CTRL, 1u);    // SRC = AUX
    while (reg(CLK_SYS_SELECTED) != (1u << 1)) {
    }
    reg(CLK_PERI_CTRL) = (1u << 11) | (0u << 5);  // ENABLE, AUXSRC = clk_sys
    // The watchdog's tick: clk_ref / 12 = 1 MHz (the timer counts it).
    reg(WATCHDOG_TICK) = WATCHDOG_TICK_ENABLE | (XOSC_HZ / 1000000u);
    unreset(RESET_TIMER);
}

}  // namespace rp2040
}  // namespace roverlink

#endif  // ROVERLINK_ARCH_RP2040
#endif  // ROVERLINK_HAL_RP2040_CLOCKS_H
