// The RP2040's start: the vector table, the reset handler (zeroes .bss, copies .data where the
// image keeps it apart, runs the static constructors, points VTOR at the table, calls main) and
// weak interrupt handlers a firmware overrides by defining `isr_<name>`. The linker script
// (ram.ld) places `.vectors` first, so an image loaded into SRAM starts at its table.
#if defined(ROVERLINK_ARCH_RP2040)

#include <stdint.h>

#include "regs.h"

extern "C" {
extern uint32_t __stack_top;
extern uint32_t __bss_start, __bss_end, __data_start, __data_end, __data_load;
extern void (*__init_array_start[])();
extern void (*__init_array_end[])();
int main();

void isr_reset();
void isr_default() {
    for (;;) {
    }
}
void isr_nmi() __attribute__((weak, alias("isr_default")));
void isr_hardfault() __attribute__((weak, alias("isr_default")));
void isr_svcall() __attribute__((weak, alias("isr_default")));
void isr_pendsv() __attribute__((weak, alias("isr_default")));
void isr_systick() __attribute__((weak, alias("isr_default")));
void isr_timer0() __attribute__((weak, alias("isr_default")));
void isr_timer1() __attribute__((weak, alias("isr_default")));
void isr_timer2() __attribute__((weak, alias("isr_default")));
void isr_timer3() __attribute__((weak, alias("isr_default")));
void isr_pwm_wrap() __attribute__((weak, alias("isr_default")));
void isr_io_bank0() __attribute__((weak, alias("isr_default")));
void isr_uart0() __attribute__((weak, alias("isr_default")));

typedef void (*Vector)();
// 16 system exceptions, then the 32 external interrupts (datasheet 2.3.2: IRQ 0-3 the timer's
// alarms, 4 PWM wrap, 13 IO_BANK0, 20 UART0).
__attribute__((section(".vectors"), used)) const Vector vector_table[48] = {
    reinterpret_cast<Vector>(&__stack_top),
    isr_reset,
    isr_nmi,
    isr_hardfault,
    0, 0, 0, 0, 0, 0, 0,
    isr_svcall,
    0, 0,
    isr_pendsv,
    isr_systick,
    isr_timer0, isr_timer1, isr_timer2, isr_timer3, isr_pwm_wrap,
    isr_default, isr_default, isr_default, isr_default, isr_default, isr_default, isr_default, isr_default,
    isr_io_bank0,
    isr_default, isr_default, isr_default, isr_default, isr_default, isr_default,
    isr_uart0,
    isr_default, isr_default, isr_default, isr_default, isr_default, isr_default, isr_default, isr_default,
    isr_default, isr_default, isr_default,
};

void isr_reset() {
    for (uint32_t* p = &__data_start, *from = &__data_load; p < &__data_end;) {
        *p++ = *from++;
    }
    for (uint32_t* p = &__bss_start; p < &__bss_end;) {
        *p++ = 0;
    }
    roverlink::rp2040::reg(roverlink::rp2040::SCB_VTOR) = reinterpret_cast<uint32_t>(&vector_table[0]);
    for (void (**f)() = __init_array_start; f < __init_array_end; ++f) {
        (*f)();
    }
    main();
    for (;;) {
    }
}
}  // extern "C"

#endif  // ROVERLINK_ARCH_RP2040
