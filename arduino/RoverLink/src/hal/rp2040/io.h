// The RP2040's pins, UART0 and PWM slices, register-level (datasheet 2.19 GPIO, 4.2 UART, 4.5
// PWM). Header-only: every call is a few register writes the compiler inlines.
//
//   rl::rp2040::Uart0::begin(115200);              // GP0 TX, GP1 RX, 8N1, FIFOs on
//   rl::rp2040::Pwm::begin(2, 125, 999);           // GP2 (slice 1 A) at 125 MHz / 125 / 1000 = 1 kHz
//   rl::rp2040::Pwm::set(2, 250);                  // 25 % high
#ifndef ROVERLINK_HAL_RP2040_IO_H
#define ROVERLINK_HAL_RP2040_IO_H

#if defined(ROVERLINK_ARCH_RP2040)

#include <stdint.h>

#include "regs.h"

namespace roverlink {
namespace rp2040 {

/// Takes blocks out of reset and waits until they are (datasheet 2.14).
inline void unreset(uint32_t blocks) {
    clear_bits(RESETS_RESET, blocks);
    while ((reg(RESETS_DONE) & blocks) != blocks) {
    }
}

inline void pin_function(unsigned pin, uint32_t function) {
    reg(pad(pin)) = PAD_IE | (reg(pad(pin)) & ~PAD_IE);
    reg(gpio_ctrl(pin)) = function;
}

/// A pin read by software (SIO), with its pull-up on when asked.
inline void input_pin(unsigned pin, bool pull_up) {
    pin_function(pin, GPIO_FUNC_SIO);
    if (pull_up) {
        set_bits(pad(pin), PAD_PUE);
    }
}

inline bool pin_level(unsigned pin) { return (reg(SIO_GPIO_IN) >> pin) & 1u; }

/// Edge interrupts of `pin` on core 0 (both edges); IRQ_IO_BANK0 must be enabled in the NVIC.
inline void pin_edges(unsigned pin) {
    const unsigned shift = 4u * (pin % 8u);
    reg(IO_INTR0 + 4u * (pin / 8u)) = (GPIO_EDGE_LOW | GPIO_EDGE_HIGH) << shift;  // clear stale edges
    set_bits(IO_PROC0_INTE0 + 4u * (pin / 8u), (GPIO_EDGE_LOW | GPIO_EDGE_HIGH) << shift);
}

/// Edges `pin` saw since the last call (0..2 bits: low, high), cleared.
inline uint32_t take_edges(unsigned pin) {
    const unsigned shift = 4u * (pin % 8u);
    const uint32_t address = IO_INTR0 + 4u * (pin / 8u);
    const uint32_t seen = (reg(address) >> shift) & (GPIO_EDGE_LOW | GPIO_EDGE_HIGH);
    reg(address) = seen << shift;
    return seen;
}

inline void enable_irq(unsigned irq) {
    reg(NVIC_ICPR) = 1u << irq;
    reg(NVIC_ISER) = 1u << irq;
}

struct Uart0 {
    static void begin(uint32_t baud) {
        unreset(RESET_IO_BANK0 | RESET_PADS_BANK0 | RESET_UART0);
        // The PL011's divisor in 1/64ths (datasheet 4.2.7.1), rounded to the nearest.
        const uint32_t div = (8u * CLK_PERI_HZ) / baud;
        reg(UART0 + UART_IBRD) = div >> 7;
        reg(UART0 + UART_FBRD) = ((div & 0x7fu) + 1u) / 2u;
        reg(UART0 + UART_LCR_H) = (3u << 5) | (1u << 4);  // 8 data bits, FIFOs on
        reg(UART0 + UART_CR) = (1u << 0) | (1u << 8) | (1u << 9);  // UARTEN, TXE, RXE
        pin_function(0, GPIO_FUNC_UART);
        pin_function(1, GPIO_FUNC_UART);
    }
    /// RX and receive-timeout interrupts (bits 4, 6): a byte waiting wakes the core from WFI.
    static void interrupt_on_receive() {
        reg(UART0 + UART_IMSC) = (1u << 4) | (1u << 6);
        enable_irq(IRQ_UART0);
    }
    static bool readable() { return !(reg(UART0 + UART_FR) & UART_FR_RXFE); }
    static uint8_t read() { return static_cast<uint8_t>(reg(UART0 + UART_DR)); }
    static bool writable() { return !(reg(UART0 + UART_FR) & UART_FR_TXFF); }
    static void write(uint8_t byte) {
        while (!writable()) {
        }
        reg(UART0 + UART_DR) = byte;
    }
};

struct Pwm {
    static unsigned slice(unsigned pin) { return (pin >> 1) & 7u; }
    /// `pin`'s slice counting 0..top at clk_sys / divider (1..255), free-running.
    static void begin(unsigned pin, uint32_t divider, uint32_t top) {
        unreset(RESET_IO_BANK0 | RESET_PADS_BANK0 | RESET_PWM);
        const unsigned s = slice(pin);
        reg(pwm_div(s)) = divider << 4;
        reg(pwm_top(s)) = top;
        pin_function(pin, GPIO_FUNC_PWM);
        set_bits(pwm_csr(s), 1u);
    }
    /// Counts of each period `pin` is high (0: low, top + 1: high).
    static void set(unsigned pin, uint32_t level) {
        const unsigned s = slice(pin);
        const unsigned shift = (pin & 1u) ? 16u : 0u;
        reg(pwm_cc(s)) = (reg(pwm_cc(s)) & ~(0xffffu << shift)) | ((level & 0xffffu) << shift);
    }
};

/// `bits` (1..32) of the ring oscillator's noise, one read each (datasheet 2.17.5: not a random
/// number generator, but enough physical noise to seed the per-boot boot_id).
inline uint32_t noise_bits(unsigned bits) {
    uint32_t value = 0;
    for (unsigned i = 0; i < bits; ++i) {
        value = (value << 1) | (reg(ROSC_RANDOMBIT) & 1u);
    }
    return value;
}

/// The microsecond timer's low word (datasheet 4.6: 1 MHz from the watchdog's tick).
inline uint32_t micros() { return reg(TIMER_TIMERAWL); }

}  // namespace rp2040
}  // namespace roverlink

#endif  // ROVERLINK_ARCH_RP2040
#endif  // ROVERLINK_HAL_RP2040_IO_H
