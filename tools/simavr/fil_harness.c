/* Firmware in the loop: a RoverLink example's ELF running in simavr, stepped by a plant driver.
 *
 *   fil_harness MCU ELF [--enc PA PB]... [--pcint-k] [--watch ADDR]... [--adc0 MV]
 *
 * MCU is atmega328p or atmega2560 (16 MHz). Each --enc gives one wheel's encoder channels as port
 * pins (e.g. --enc E4 E5 for Mega pins 2 and 3); --watch ADDR adds a data-space address (decimal
 * or 0x..) whose byte is reported after every step (timer compare registers, TCCRnA, PORTx...).
 * --pcint-k models the Mega's PCINT2 (port K, PCINT16..23), which simavr 1.6 lacks: an edge on a
 * port K pin enabled in PCMSK2 raises PCINT2_vect while PCICR.PCIE2 is set.
 *
 * The driver (emulator/backends/simavr.py) owns the plant and the clock and sends one command per
 * line on stdin; each gets one reply line on stdout:
 *
 *   S <us> <count0> ... <countN-1> <hex|->  feed host bytes to UART0 (simavr paces them at the baud
 *                                           rate), move each encoder to its absolute count with
 *                                           quadrature edges spread evenly over the step, run <us>
 *                                           microseconds of MCU time. Reply:
 *                                           O <cycle> <watched bytes as hex> <uart out hex|->
 *   R                                       reset the MCU (reset pin: SRAM and I/O reset, EEPROM and
 *                                           encoder positions kept). Reply: OK <cycle>
 *   T <addr>                                read a 16-bit little-endian value in data space (ground
 *                                           truth / benchmarks). Reply: V <value>
 *   C                                       cycle statistics since the last C: the longest time
 *                                           (cycles) from a UART byte entering UDR0 to the RX
 *                                           interrupt reading it, and overruns. Reply:
 *                                           C <max_rx_latency_cycles> <bytes> <overruns>
 *   L <byte address>                        loop marker: the address of a function the sketch's main
 *                                           loop calls once per pass (serialEventRun). Reply: OK
 *   M                                       loop statistics since the last M: passes, cycles, the
 *                                           shortest and the longest pass. Reply:
 *                                           M <passes> <cycles> <min> <max>
 *   Q                                       quit (reply: BYE)
 *
 * After loading, the harness prints `READY <mcu>` (simavr's ELF loader may print before it).
 *
 * Nothing here sleeps or reads the wall clock: time is simavr's cycle counter, so a run is
 * deterministic for a given ELF and command sequence. Pacing to real time is the driver's job.
 */
#include <inttypes.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <simavr/avr_adc.h>
#include <simavr/avr_extint.h>
#include <simavr/avr_ioport.h>
#include <simavr/avr_uart.h>
#include <simavr/sim_avr.h>
#include <simavr/sim_elf.h>
#include <simavr/sim_interrupts.h>
#include <simavr/sim_io.h>

#define F_CPU_HZ 16000000u
#define CYCLES_PER_US 16u
#define MAX_WHEELS 4
#define MAX_WATCH 64
#define MAX_LINE 65536
#define MAX_OUT 65536

/* ATmega2560 pin-change registers (data-space addresses) and vector. */
#define M2560_PCIFR 0x3B
#define M2560_PCICR 0x68
#define M2560_PCMSK2 0x6D
#define M2560_PCINT2_VECTOR 11

/* UART0 data-space addresses, the same on both MCUs. */
#define UCSR0A 0xC0
#define UDR0 0xC6

typedef struct {
    avr_irq_t* a;
    avr_irq_t* b;
    char port_a, port_b;
    int bit_a, bit_b;
    int32_t position; /* edges from power-up; Gray phase = position mod 4 */
} encoder_t;

static avr_t* avr;
static encoder_t encoders[MAX_WHEELS];
static int encoder_count;
static uint16_t watch[MAX_WATCH];
static int watch_count;
static uint8_t out_bytes[MAX_OUT];
static size_t out_count;
static int pcint_k;
static avr_int_vector_t pcint2_vector;
static uint8_t port_k_level;

/* RX latency bookkeeping: a byte enters UDR0 when RXC0 rises; it is processed when RXC0 falls. */
static uint64_t rx_since;
static int rx_pending;
static uint64_t rx_max_latency;
static uint64_t rx_bytes;
static uint64_t rx_overruns;

static void on_uart_out(struct avr_irq_t* irq, uint32_t value, void* param) {
    (void)irq;
    (void)param;
    if (out_count < MAX_OUT) out_bytes[out_count++] = (uint8_t)value;
}

static avr_irq_t* pin_irq(char port, int bit) {
    avr_irq_t* irq = avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(port), bit);
    if (irq == NULL) {
        fprintf(stderr, "fil_harness: no port %c on this MCU\n", port);
        exit(2);
    }
    return irq;
}

static void parse_pin(const char* s, char* port, int* bit) {
    if (strlen(s) != 2 || s[0] < 'A' || s[0] > 'L' || s[1] < '0' || s[1] > '7') {
        fprintf(stderr, "fil_harness: bad pin %s (want e.g. E4)\n", s);
        exit(2);
    }
    *port = s[0];
    *bit = s[1] - '0';
}

/* Gray code of a position: forward walks AB 00 -> 10 -> 11 -> 01 (quadrature.h). Position 0 is
 * 11, the level of an idle open-collector encoder on pull-ups (and not a low level, which would keep
 * simavr polling a level-triggered INTn before the sketch attaches its CHANGE interrupt). */
static void levels(int32_t position, int* a, int* b) {
    static const int A[4] = {1, 0, 0, 1};
    static const int B[4] = {1, 1, 0, 0};
    const int phase = (int)(((position % 4) + 4) % 4);
    *a = A[phase];
    *b = B[phase];
}

static void pin_change_k(char port, int bit, int level) {
    if (!pcint_k || port != 'K') return;
    const uint8_t mask = (uint8_t)(1u << bit);
    const uint8_t old = port_k_level;
    port_k_level = level ? (uint8_t)(old | mask) : (uint8_t)(old & ~mask);
    if (old != port_k_level && (avr->data[M2560_PCMSK2] & mask) != 0) avr_raise_interrupt(avr, &pcint2_vector);
}

/* The level an input pin shows, as simavr's "external" pull state of its port: otherwise a
 * pinMode(INPUT_PULLUP) after a reset would read the internal pull-up (1) instead of the encoder. */
static uint8_t ext_mask[12], ext_value[12];

static void set_external(char port, int bit, int level) {
    const int i = port - 'A';
    const uint8_t m = (uint8_t)(1u << bit);
    ext_mask[i] |= m;
    ext_value[i] = level ? (uint8_t)(ext_value[i] | m) : (uint8_t)(ext_value[i] & ~m);
    avr_ioport_external_t ext = {.name = (unsigned long)port, .mask = ext_mask[i], .value = ext_value[i]};
    avr_ioctl(avr, AVR_IOCTL_IOPORT_SET_EXTERNAL(port), &ext);
}

static void drive_encoder(encoder_t* e) {
    int a = 0, b = 0;
    levels(e->position, &a, &b);
    set_external(e->port_a, e->bit_a, a);
    set_external(e->port_b, e->bit_b, b);
    avr_raise_irq(e->a, (uint32_t)a);
    avr_raise_irq(e->b, (uint32_t)b);
    pin_change_k(e->port_a, e->bit_a, a);
    pin_change_k(e->port_b, e->bit_b, b);
}

static void track_rx(void) {
    const int rxc = (avr->data[UCSR0A] & 0x80) != 0;
    if (rxc && !rx_pending) {
        rx_pending = 1;
        rx_since = avr->cycle;
    } else if (!rxc && rx_pending) {
        rx_pending = 0;
        const uint64_t latency = avr->cycle - rx_since;
        if (latency > rx_max_latency) rx_max_latency = latency;
        ++rx_bytes;
    }
    static int dor;
    const int dor_now = (avr->data[UCSR0A] & 0x08) != 0; /* DOR0, counted on its rising edge */
    if (dor_now && !dor) ++rx_overruns;
    dor = dor_now;
}

/* Main-loop passes: each time the PC reaches the marker. The shortest pass is poll() with nothing
 * to do; cycles beyond passes * shortest are work (ticks, frames, interrupts). */
static avr_flashaddr_t loop_marker;
static uint64_t loop_last, loop_passes, loop_cycles_from, loop_min = UINT64_MAX, loop_max;

static void track_loop(void) {
    if (loop_marker == 0 || avr->pc != loop_marker) return;
    if (loop_last != 0) {
        const uint64_t len = avr->cycle - loop_last;
        if (len < loop_min) loop_min = len;
        if (len > loop_max) loop_max = len;
        ++loop_passes;
    } else {
        loop_cycles_from = avr->cycle;
    }
    loop_last = avr->cycle;
}

static int run_until(uint64_t end) {
    while (avr->cycle < end) {
        const int state = avr_run(avr);
        if (state == cpu_Done || state == cpu_Crashed) {
            fprintf(stderr, "fil_harness: the firmware stopped (state %d) at cycle %" PRIu64 "\n", state,
                    (uint64_t)avr->cycle);
            return 0;
        }
        track_rx();
        track_loop();
    }
    return 1;
}

static int hexval(int c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

static int cmd_step(char* args) {
    char* save = NULL;
    char* tok = strtok_r(args, " \t\n", &save);
    if (tok == NULL) return 0;
    const uint64_t us = strtoull(tok, NULL, 10);
    int32_t target[MAX_WHEELS];
    for (int w = 0; w < encoder_count; ++w) {
        tok = strtok_r(NULL, " \t\n", &save);
        if (tok == NULL) return 0;
        target[w] = (int32_t)strtol(tok, NULL, 10);
    }
    tok = strtok_r(NULL, " \t\n", &save);
    if (tok == NULL) return 0;
    if (strcmp(tok, "-") != 0) {
        avr_irq_t* in = avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT);
        for (size_t i = 0; tok[i] && tok[i + 1]; i += 2) {
            const int hi = hexval(tok[i]), lo = hexval(tok[i + 1]);
            if (hi < 0 || lo < 0) return 0;
            avr_raise_irq(in, (uint32_t)(hi * 16 + lo));
        }
    }
    const uint64_t start = avr->cycle;
    const uint64_t span = us * CYCLES_PER_US;
    /* Edges of all wheels, evenly spread: edge k of n at start + span * (k + 1) / (n + 1). */
    int64_t n[MAX_WHEELS];
    int64_t done[MAX_WHEELS];
    for (int w = 0; w < encoder_count; ++w) {
        n[w] = (int64_t)target[w] - (int64_t)encoders[w].position;
        done[w] = 0;
    }
    for (;;) {
        uint64_t next = start + span;
        int who = -1;
        for (int w = 0; w < encoder_count; ++w) {
            const int64_t total = n[w] < 0 ? -n[w] : n[w];
            if (done[w] >= total) continue;
            const uint64_t at = start + span * (uint64_t)(done[w] + 1) / (uint64_t)(total + 1);
            if (at < next || who < 0) {
                if (at <= next) {
                    next = at;
                    who = w;
                }
            }
        }
        if (!run_until(next)) return -1;
        if (who < 0) break;
        encoders[who].position += n[who] < 0 ? -1 : 1;
        ++done[who];
        drive_encoder(&encoders[who]);
    }
    printf("O %" PRIu64 " ", (uint64_t)avr->cycle);
    for (int i = 0; i < watch_count; ++i) printf("%02x", avr->data[watch[i]]);
    if (watch_count == 0) printf("-");
    printf(" ");
    for (size_t i = 0; i < out_count; ++i) printf("%02x", out_bytes[i]);
    if (out_count == 0) printf("-");
    printf("\n");
    out_count = 0;
    return 1;
}

static void configure_uart(void) {
    uint32_t flags = 0;
    avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
    flags &= ~(uint32_t)(AVR_UART_FLAG_STDIO | AVR_UART_FLAG_POLL_SLEEP);
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
}

static void after_reset(uint32_t adc_mv) {
    configure_uart();
    /* No sketch uses level-triggered INTn; simavr's strict level mode polls a low INT pin (a PWM
     * output that shares it, on the BTS7960 board) every few cycles, which costs 8x in speed. */
    for (uint8_t i = 0; i < EXTINT_COUNT; ++i) avr_extint_set_strict_lvl_trig(avr, i, 0);
    avr->avcc = avr->aref = 5000;
    avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_ADC0), adc_mv);
    for (int w = 0; w < encoder_count; ++w) drive_encoder(&encoders[w]);
    rx_pending = 0;
}

int main(int argc, char** argv) {
    if (argc < 3) {
        fprintf(stderr, "usage: %s MCU ELF [--enc PA PB]... [--pcint-k] [--watch ADDR]... [--adc0 MV]\n", argv[0]);
        return 2;
    }
    uint32_t adc_mv = 1234;
    for (int i = 3; i < argc; ++i) {
        if (strcmp(argv[i], "--enc") == 0 && i + 2 < argc && encoder_count < MAX_WHEELS) {
            encoder_t* e = &encoders[encoder_count++];
            parse_pin(argv[i + 1], &e->port_a, &e->bit_a);
            parse_pin(argv[i + 2], &e->port_b, &e->bit_b);
            i += 2;
        } else if (strcmp(argv[i], "--watch") == 0 && i + 1 < argc && watch_count < MAX_WATCH) {
            watch[watch_count++] = (uint16_t)strtoul(argv[++i], NULL, 0);
        } else if (strcmp(argv[i], "--pcint-k") == 0) {
            pcint_k = 1;
        } else if (strcmp(argv[i], "--adc0") == 0 && i + 1 < argc) {
            adc_mv = (uint32_t)strtoul(argv[++i], NULL, 0);
        } else {
            fprintf(stderr, "fil_harness: bad argument %s\n", argv[i]);
            return 2;
        }
    }
    elf_firmware_t fw;
    memset(&fw, 0, sizeof fw);
    if (elf_read_firmware(argv[2], &fw) != 0) {
        fprintf(stderr, "fil_harness: cannot read %s\n", argv[2]);
        return 2;
    }
    strncpy(fw.mmcu, argv[1], sizeof fw.mmcu - 1);
    fw.frequency = F_CPU_HZ;
    avr = avr_make_mcu_by_name(fw.mmcu);
    if (avr == NULL) {
        fprintf(stderr, "fil_harness: simavr does not know %s\n", fw.mmcu);
        return 2;
    }
    avr_init(avr);
    avr->log = getenv("FIL_LOG") ? (uint8_t)atoi(getenv("FIL_LOG")) : 0;
    avr_load_firmware(avr, &fw);
    for (int i = 0; i < watch_count; ++i) {
        if (watch[i] > avr->ramend) {
            fprintf(stderr, "fil_harness: watch address 0x%x is outside the data space\n", watch[i]);
            return 2;
        }
    }
    if (pcint_k) {
        if (strcmp(fw.mmcu, "atmega2560") != 0) {
            fprintf(stderr, "fil_harness: --pcint-k is for the atmega2560\n");
            return 2;
        }
        memset(&pcint2_vector, 0, sizeof pcint2_vector);
        pcint2_vector.vector = M2560_PCINT2_VECTOR;
        pcint2_vector.enable = (avr_regbit_t)AVR_IO_REGBIT(M2560_PCICR, 2);
        pcint2_vector.raised = (avr_regbit_t)AVR_IO_REGBIT(M2560_PCIFR, 2);
        avr_register_vector(avr, &pcint2_vector);
    }
    for (int w = 0; w < encoder_count; ++w) {
        encoders[w].a = pin_irq(encoders[w].port_a, encoders[w].bit_a);
        encoders[w].b = pin_irq(encoders[w].port_b, encoders[w].bit_b);
    }
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT), on_uart_out, NULL);
    after_reset(adc_mv);

    static char line[MAX_LINE];
    setvbuf(stdout, NULL, _IOFBF, 1 << 16);
    printf("READY %s\n", fw.mmcu); /* simavr's loader prints to stdout before this: skip to here */
    fflush(stdout);
    while (fgets(line, sizeof line, stdin) != NULL) {
        int ok = 1;
        switch (line[0]) {
            case 'S': {
                const int r = cmd_step(line + 1);
                if (r < 0) return 1;
                ok = r;
                break;
            }
            case 'R':
                avr_reset(avr);
                out_count = 0;
                after_reset(adc_mv);
                printf("OK %" PRIu64 "\n", (uint64_t)avr->cycle);
                break;
            case 'T': {
                const unsigned long addr = strtoul(line + 1, NULL, 0);
                if (addr + 1 > avr->ramend) {
                    ok = 0;
                    break;
                }
                printf("V %u\n", (unsigned)(avr->data[addr] | (avr->data[addr + 1] << 8)));
                break;
            }
            case 'C':
                printf("C %" PRIu64 " %" PRIu64 " %" PRIu64 "\n", rx_max_latency, rx_bytes, rx_overruns);
                rx_max_latency = rx_bytes = rx_overruns = 0;
                break;
            case 'L':
                loop_marker = (avr_flashaddr_t)strtoul(line + 1, NULL, 0);
                loop_last = loop_passes = loop_max = 0;
                loop_min = UINT64_MAX;
                printf("OK\n");
                break;
            case 'M':
                printf("M %" PRIu64 " %" PRIu64 " %" PRIu64 " %" PRIu64 "\n", loop_passes,
                       loop_last > loop_cycles_from ? loop_last - loop_cycles_from : 0,
                       loop_passes ? loop_min : 0, loop_max);
                loop_passes = loop_max = 0;
                loop_min = UINT64_MAX;
                loop_cycles_from = loop_last;
                break;
            case 'Q':
                printf("BYE\n");
                fflush(stdout);
                return 0;
            default:
                ok = 0;
        }
        if (!ok) printf("ERR %s", line);
        fflush(stdout);
    }
    return 0;
}
