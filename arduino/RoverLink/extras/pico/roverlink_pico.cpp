// The RoverLink firmware on a Raspberry Pi Pico: the portable core over the RP2040 hardware layer,
// for any robot file with board = "pico" (`roverlink firmware build --robot FILE` generates its
// robot_profile.h beside this file and builds the ELF and UF2; docs/firmware.md, "Raspberry Pi
// Pico"). The host link is UART0 on GP0 (TX) and GP1 (RX).
//
// The core sleeps (WFI) between control ticks: a timer alarm at the next tick and the UART's
// receive interrupt wake it. The watchdog resets the chip if the loop stops for WATCHDOG_MS.
#include <RoverLink.h>

#include "robot_profile.h"

namespace rl = roverlink::rp2040;

#if !defined(ROVERLINK_BAUD)
#define ROVERLINK_BAUD 115200
#endif

static const uint32_t WATCHDOG_MS = 100;  // ten control ticks

static rl::UartStream port;
static rl::Rp2040Board board(robot_profile::WIRING);
static const rl::Watchdog watchdog(WATCHDOG_MS);
static const roverlink::Robot ROBOT = {robot_profile::NAME,           robot_profile::BOARD,
                                       robot_profile::CAPABILITIES,   robot_profile::FEEDBACK_MODE,
                                       robot_profile::default_config, robot_profile::default_pid,
                                       robot_profile::LIGHTS_MODE};
static roverlink::Firmware firmware(port, board, ROBOT);

extern "C" void isr_io_bank0() { board.on_pin_interrupt(); }
extern "C" void isr_uart0() { port.on_interrupt(); }
extern "C" void isr_timer0() { rl::reg(rl::TIMER_INTR) = 1u; }  // the wake-up alarm: only wakes

// Sleeps until the next control tick or a received byte. Interrupts are off from the check to the
// WFI, which still wakes on a pending one: a byte arriving in between is never slept through.
static void sleep_until(uint32_t wake_us) {
    rl::InterruptsOff off;
    if (port.available() != 0 || static_cast<int32_t>(wake_us - rl::micros()) <= 0) {
        return;
    }
    rl::reg(rl::TIMER_ALARM0) = wake_us;  // arms alarm 0
    __asm volatile("wfi" ::: "memory");
}

int main() {
    rl::clocks_begin();
    board.begin();  // motors coasting and LEDs off before anything else runs
    rl::reg(rl::TIMER_INTE) = 1u;
    rl::enable_irq(rl::IRQ_TIMER0);
    port.begin(ROVERLINK_BAUD);
    firmware.begin();
    watchdog.begin();
    for (;;) {
        firmware.poll();
        watchdog.feed();
        sleep_until(firmware.next_tick_us());
    }
}
