// The RP2040's registers this layer uses, by address (RP2040 datasheet, chapter 2 and the
// peripherals' chapters): no Pico SDK. Each block has atomic XOR/SET/CLR aliases at +0x1000,
// +0x2000 and +0x3000 (datasheet 2.1.2), used so that a read-modify-write never races an IRQ.
#ifndef ROVERLINK_HAL_RP2040_REGS_H
#define ROVERLINK_HAL_RP2040_REGS_H

#include <stdint.h>

namespace roverlink {
namespace rp2040 {

inline volatile uint32_t& reg(uint32_t address) { return *reinterpret_cast<volatile uint32_t*>(address); }
inline void set_bits(uint32_t address, uint32_t mask) { reg(address + 0x2000u) = mask; }
inline void clear_bits(uint32_t address, uint32_t mask) { reg(address + 0x3000u) = mask; }

const uint32_t RESETS = 0x4000c000u;
const uint32_t RESETS_RESET = RESETS + 0x0u;
const uint32_t RESETS_DONE = RESETS + 0x8u;
const uint32_t RESET_IO_BANK0 = 1u << 5;
const uint32_t RESET_PADS_BANK0 = 1u << 8;
const uint32_t RESET_PWM = 1u << 14;
const uint32_t RESET_TIMER = 1u << 21;
const uint32_t RESET_UART0 = 1u << 22;

const uint32_t IO_BANK0 = 0x40014000u;
inline uint32_t gpio_ctrl(unsigned pin) { return IO_BANK0 + 8u * pin + 4u; }
const uint32_t IO_INTR0 = IO_BANK0 + 0x0f0u;          // raw edge status, 4 bits per pin, write 1 to clear
const uint32_t IO_PROC0_INTE0 = IO_BANK0 + 0x100u;    // core 0's enables
const uint32_t IO_PROC0_INTS0 = IO_BANK0 + 0x120u;    // core 0's enabled and pending
const uint32_t GPIO_FUNC_UART = 2u;
const uint32_t GPIO_FUNC_PWM = 4u;
const uint32_t GPIO_FUNC_SIO = 5u;
const uint32_t GPIO_EDGE_LOW = 1u << 2;   // per pin nibble: level low, level high, edge low, edge high
const uint32_t GPIO_EDGE_HIGH = 1u << 3;

const uint32_t PADS_BANK0 = 0x4001c000u;
inline uint32_t pad(unsigned pin) { return PADS_BANK0 + 4u + 4u * pin; }
const uint32_t PAD_IE = 1u << 6;          // input enable
const uint32_t PAD_PUE = 1u << 3;         // pull-up

const uint32_t UART0 = 0x40034000u;
const uint32_t UART_DR = 0x000u;
const uint32_t UART_FR = 0x018u;
const uint32_t UART_IBRD = 0x024u;
const uint32_t UART_FBRD = 0x028u;
const uint32_t UART_LCR_H = 0x02cu;
const uint32_t UART_CR = 0x030u;
const uint32_t UART_IMSC = 0x038u;
const uint32_t UART_FR_RXFE = 1u << 4;
const uint32_t UART_FR_TXFF = 1u << 5;

const uint32_t PWM = 0x40050000u;
inline uint32_t pwm_csr(unsigned slice) { return PWM + 0x14u * slice + 0x0u; }
inline uint32_t pwm_div(unsigned slice) { return PWM + 0x14u * slice + 0x4u; }
inline uint32_t pwm_cc(unsigned slice) { return PWM + 0x14u * slice + 0xcu; }
inline uint32_t pwm_top(unsigned slice) { return PWM + 0x14u * slice + 0x10u; }

const uint32_t TIMER = 0x40054000u;
const uint32_t TIMER_ALARM0 = TIMER + 0x10u;
const uint32_t TIMER_TIMERAWH = TIMER + 0x24u;
const uint32_t TIMER_TIMERAWL = TIMER + 0x28u;
const uint32_t TIMER_INTR = TIMER + 0x34u;
const uint32_t TIMER_INTE = TIMER + 0x38u;

const uint32_t WATCHDOG = 0x40058000u;
const uint32_t WATCHDOG_CTRL = WATCHDOG + 0x00u;
const uint32_t WATCHDOG_LOAD = WATCHDOG + 0x04u;
const uint32_t WATCHDOG_REASON = WATCHDOG + 0x08u;
const uint32_t WATCHDOG_TICK = WATCHDOG + 0x2cu;
const uint32_t WATCHDOG_CTRL_ENABLE = 1u << 30;
const uint32_t WATCHDOG_TICK_ENABLE = 1u << 9;

const uint32_t PSM = 0x40010000u;
const uint32_t PSM_WDSEL = PSM + 0x08u;  // what a watchdog reset resets

const uint32_t CLOCKS = 0x40008000u;
const uint32_t CLK_REF_CTRL = CLOCKS + 0x30u;
const uint32_t CLK_REF_SELECTED = CLOCKS + 0x38u;
const uint32_t CLK_SYS_CTRL = CLOCKS + 0x3cu;
const uint32_t CLK_SYS_SELECTED = CLOCKS + 0x44u;
const uint32_t CLK_PERI_CTRL = CLOCKS + 0x48u;

const uint32_t XOSC = 0x40024000u;
const uint32_t XOSC_CTRL = XOSC + 0x00u;
const uint32_t XOSC_STATUS = XOSC + 0x04u;
const uint32_t XOSC_STARTUP = XOSC + 0x0cu;

const uint32_t PLL_SYS = 0x40028000u;
const uint32_t PLL_CS = PLL_SYS + 0x0u;
const uint32_t PLL_PWR = PLL_SYS + 0x4u;
const uint32_t PLL_FBDIV_INT = PLL_SYS + 0x8u;
const uint32_t PLL_PRIM = PLL_SYS + 0xcu;
const uint32_t RESET_PLL_SYS = 1u << 12;

const uint32_t ROSC_RANDOMBIT = 0x4006001cu;  // bit 0: the ring oscillator's output, sampled

const uint32_t SIO = 0xd0000000u;
const uint32_t SIO_GPIO_IN = SIO + 0x004u;
const uint32_t SIO_GPIO_OUT_SET = SIO + 0x014u;
const uint32_t SIO_GPIO_OUT_CLR = SIO + 0x018u;
const uint32_t SIO_GPIO_OE_SET = SIO + 0x024u;

const uint32_t PPB = 0xe0000000u;
const uint32_t NVIC_ISER = PPB + 0xe100u;
const uint32_t NVIC_ICPR = PPB + 0xe280u;
const uint32_t SCB_VTOR = PPB + 0xed08u;

const unsigned IRQ_TIMER0 = 0;
const unsigned IRQ_IO_BANK0 = 13;
const unsigned IRQ_UART0 = 20;

const uint32_t XOSC_HZ = 12000000u;        // the Pico's crystal
const uint32_t CLK_SYS_HZ = 125000000u;    // clocks.h: PLL_SYS from the crystal (rp2040js' fixed rate)
const uint32_t CLK_PERI_HZ = CLK_SYS_HZ;   // clk_peri runs from clk_sys

}  // namespace rp2040
}  // namespace roverlink

#endif  // ROVERLINK_HAL_RP2040_REGS_H
