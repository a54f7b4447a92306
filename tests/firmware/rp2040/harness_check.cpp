// The rp2040js harness's own check (tests/emulator/backends/test_rp2040_harness.py): a firmware
// small enough to be obviously right, so a harness fault is not read as a firmware fault.
//
// - UART0 at 115200 echoes every byte, except 0xFF, answered with the edges counted so far on GP4
//   and GP5 (two little-endian u32), 0xFE, answered with the microsecond timer's low word, and
//   0xFD, answered with 32 bits of the ring oscillator's noise;
// - GP2 (PWM slice 1, channel A) runs at 1 kHz, 25 % high; GP3 (channel B) 60 %;
// - GP4 and GP5 are inputs with edge interrupts (the encoder pins of the real firmware);
// - between bytes the core sleeps (WFI), woken by UART0's receive interrupt.
#include <stdint.h>

#include "hal/rp2040/io.h"

namespace rp = roverlink::rp2040;

namespace {

volatile uint32_t edges[2];
volatile uint8_t rx[64];
volatile uint8_t rx_head;
uint8_t rx_tail;

void write_u32(uint32_t value) {
    for (unsigned i = 0; i < 4; ++i) {
        rp::Uart0::write(static_cast<uint8_t>(value >> (8u * i)));
    }
}

}  // namespace

extern "C" void isr_io_bank0() {
    for (unsigned k = 0; k < 2; ++k) {
        const uint32_t seen = rp::take_edges(4 + k);
        edges[k] += ((seen & rp::GPIO_EDGE_LOW) ? 1u : 0u) + ((seen & rp::GPIO_EDGE_HIGH) ? 1u : 0u);
    }
}

extern "C" void isr_uart0() {
    while (rp::Uart0::readable()) {
        rx[rx_head % sizeof rx] = rp::Uart0::read();
        rx_head = static_cast<uint8_t>(rx_head + 1);
    }
}

int main() {
    rp::Uart0::begin(115200);
    rp::Pwm::begin(2, 125, 999);
    rp::Pwm::set(2, 250);
    rp::Pwm::set(3, 600);
    rp::pin_function(3, rp::GPIO_FUNC_PWM);
    rp::input_pin(4, true);
    rp::input_pin(5, true);
    rp::pin_edges(4);
    rp::pin_edges(5);
    rp::enable_irq(rp::IRQ_IO_BANK0);
    rp::Uart0::interrupt_on_receive();
    for (;;) {
        __asm volatile("cpsid i");
        if (rx_tail == rx_head) {
            __asm volatile("wfi");  // wakes on a pending interrupt even with PRIMASK set
        }
        __asm volatile("cpsie i");
        while (rx_tail != rx_head) {
            const uint8_t byte = rx[rx_tail % sizeof rx];
            rx_tail = static_cast<uint8_t>(rx_tail + 1);
            if (byte == 0xff) {
                write_u32(edges[0]);
                write_u32(edges[1]);
            } else if (byte == 0xfe) {
                write_u32(rp::micros());
            } else if (byte == 0xfd) {
                write_u32(rp::noise_bits(32));
            } else {
                rp::Uart0::write(byte);
            }
        }
    }
}
