/* Runs an AVR firmware in simavr, drives input pins on a schedule and logs output pins and UART0.
 *
 *   sim_pins MCU ELF DURATION_US [WATCH...] < schedule
 *
 * WATCH is a port pin such as B1 (Uno pin 9) or H3 (Mega pin 6), or @ADDR (data-space address,
 * e.g. @0x80 for TCCR1A) for a register to print at the end. The schedule on stdin has one
 * "<time_us> <port pin> <0|1>" line per input change, in time order. Output, one line each:
 *
 *   PIN <cycle> <port pin> <level>     every change of a watched pin (16 cycles per microsecond)
 *   REG <addr> <value>                 each @ADDR register at the end (decimal)
 *   UART <hex>                         every byte UART0 sent, at the end
 *
 * Registers rather than waveforms for the timers: simavr 1.6 does not model the compare outputs
 * of a 16-bit timer in fast PWM mode 14 faithfully, while its register file is exact.
 *
 * Used by tests/firmware/test_avr_hal_sim.py to check the AVR hardware layer's timers, PWM,
 * direction pins and encoder interrupts on the real instruction set and peripheral models.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <simavr/avr_ioport.h>
#include <simavr/avr_uart.h>
#include <simavr/sim_avr.h>
#include <simavr/sim_elf.h>

#define MAX_WATCH 32
#define MAX_UART 65536

static avr_t* avr;
static uint8_t uart_bytes[MAX_UART];
static size_t uart_count;

static uint64_t now_cycles(void) { return (uint64_t)avr->cycle; }

#define CYCLES_PER_US 16ull

static void on_pin(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq;
    const char* name = (const char*)param;
    printf("PIN %llu %s %u\n", (unsigned long long)now_cycles(), name, value ? 1u : 0u);
}

static void on_uart(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq;
    (void)param;
    if (uart_count < MAX_UART) uart_bytes[uart_count++] = (uint8_t)value;
}

static avr_irq_t* pin_irq(const char* name) {
    if (strlen(name) != 2 || name[0] < 'A' || name[0] > 'L' || name[1] < '0' || name[1] > '7') {
        fprintf(stderr, "bad pin name %s (want e.g. B1)\n", name);
        exit(2);
    }
    avr_irq_t* irq = avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(name[0]), name[1] - '0');
    if (irq == NULL) {
        fprintf(stderr, "no port %c on this MCU\n", name[0]);
        exit(2);
    }
    return irq;
}

int main(int argc, char** argv) {
    if (argc < 4) {
        fprintf(stderr, "usage: %s MCU ELF DURATION_US [WATCH...] < schedule\n", argv[0]);
        return 2;
    }
    elf_firmware_t fw;
    memset(&fw, 0, sizeof fw);
    if (elf_read_firmware(argv[2], &fw) != 0) {
        fprintf(stderr, "cannot read %s\n", argv[2]);
        return 2;
    }
    strncpy(fw.mmcu, argv[1], sizeof fw.mmcu - 1);
    fw.frequency = 16000000; /* CYCLES_PER_US */
    avr = avr_make_mcu_by_name(fw.mmcu);
    if (avr == NULL) {
        fprintf(stderr, "simavr does not know %s\n", fw.mmcu);
        return 2;
    }
    avr_init(avr);
    avr->log = 0;
    avr_load_firmware(avr, &fw);

    /* UART0: no console echo, and no sleeping while the firmware polls for input (it always does). */
    uint32_t flags = 0;
    avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
    flags &= ~(uint32_t)(AVR_UART_FLAG_STDIO | AVR_UART_FLAG_POLL_SLEEP);
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT), on_uart, NULL);

    for (int i = 4; i < argc && i - 4 < MAX_WATCH; ++i) {
        if (argv[i][0] != '@') avr_irq_register_notify(pin_irq(argv[i]), on_pin, argv[i]);
    }

    const uint64_t end = strtoull(argv[3], NULL, 10) * CYCLES_PER_US;
    unsigned long long at_us = 0;
    char name[8];
    unsigned level = 0;
    int have_event = scanf("%llu %7s %u", &at_us, name, &level) == 3;
    for (;;) {
        const uint64_t t = now_cycles();
        if (t >= end) break;
        while (have_event && at_us * CYCLES_PER_US <= t) {
            avr_raise_irq(pin_irq(name), level ? 1 : 0);
            have_event = scanf("%llu %7s %u", &at_us, name, &level) == 3;
        }
        const int state = avr_run(avr);
        if (state == cpu_Done || state == cpu_Crashed) {
            fprintf(stderr, "the firmware stopped (state %d) at cycle %llu\n", state, (unsigned long long)t);
            return 1;
        }
    }
    for (int i = 4; i < argc; ++i) {
        if (argv[i][0] != '@') continue;
        const unsigned long addr = strtoul(argv[i] + 1, NULL, 0);
        if (addr > avr->ramend) {
            fprintf(stderr, "register address %s is outside the data space\n", argv[i]);
            return 2;
        }
        printf("REG %s %u\n", argv[i] + 1, avr->data[addr]);
    }
    printf("UART ");
    for (size_t i = 0; i < uart_count; ++i) printf("%02x", uart_bytes[i]);
    printf("\n");
    return 0;
}
