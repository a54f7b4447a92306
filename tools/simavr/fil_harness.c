/* Firmware in the loop: a RoverLink example's ELF running in simavr, stepped by a plant driver.
 *
 *   fil_harness MCU ELF [--enc PA PB]... [--pcint-k] [--watch ADDR]... [--adc0 MV] [--line-ppb N]
 *
 * MCU is atmega328p or atmega2560 (16 MHz). Each --enc gives one wheel's encoder channels as port
 * pins (e.g. --enc E4 E5 for Mega pins 2 and 3); --watch ADDR adds a data-space address (decimal
 * or 0x..) whose byte is reported after every step (timer compare registers, TCCRnA, PORTx...).
 * --pcint-k models the Mega's PCINT2 (port K, PCINT16..23), which simavr 1.6 lacks: an edge on a
 * port K pin enabled in PCMSK2 raises PCINT2_vect while PCICR.PCIE2 is set. --line-ppb N: the MCU's
 * clock runs N parts per billion fast against the host's (the driver's --drift-ppm), so a received
 * bit, paced by the host, lasts 1 + N/1e9 times the nominal 1250/9 cycles.
 *
 * The driver (emulator/backends/simavr/) owns the plant and the clock and sends one command per
 * line on stdin; each gets one reply line on stdout:
 *
 *   S <us> <count0> ... <countN-1> <hex|->  queue host bytes on UART0's line (sent back to back at
 *                                           115200 baud from now or from the end of the bytes still
 *                                           queued), move each encoder to its absolute count with
 *                                           quadrature edges spread evenly over the step, run <us>
 *                                           microseconds of MCU time. Reply:
 *                                           O <cycle> <watched bytes as hex> <uart out hex|->
 *   R                                       reset the MCU (reset pin: SRAM and I/O reset, EEPROM and
 *                                           encoder positions kept; bytes on the line are lost).
 *                                           Reply: OK <cycle>
 *   T <addr>                                read a 16-bit little-endian value in data space (ground
 *                                           truth / benchmarks). Reply: V <value>
 *   C                                       receive statistics since the last C: the longest time
 *                                           (cycles) from a byte's stop bit to the firmware reading
 *                                           it from UDR0, the bytes read, and the bytes lost to
 *                                           overruns (see "UART0 receive" below). Reply:
 *                                           C <max_rx_latency_cycles> <bytes> <overruns>
 *   L <byte address>                        loop marker: the address of a function the sketch's main
 *                                           loop calls once per pass (serialEventRun). Reply: OK
 *   M                                       loop statistics since the last M: passes, cycles, the
 *                                           shortest and the longest pass. Reply:
 *                                           M <passes> <cycles> <min> <max>
 *   P <byte address>                        profile calls of the function at that address (0: stop):
 *                                           while the CPU is inside a call (from the PC reaching the
 *                                           address until SP rises above its value there) and not in
 *                                           an interrupt handler, each instruction's cycles are added
 *                                           to its PC. Reply: OK
 *   H <byte address>                        a handler boundary of the profile (0 clears them; at
 *                                           most 16): inside a profiled call, the cycles of a call of
 *                                           that function (until SP rises above its value at entry)
 *                                           are added to PC + 0x1000000 instead of PC, so a dump
 *                                           tells decoding and dispatching from what the handlers
 *                                           and the replies cost. Reply: OK
 *   D                                       dump and reset the profile: calls, cycles, the cheapest
 *                                           call, the longest call less its handlers' cycles, then
 *                                           <byte address hex>:<cycles> per PC (or -). Reply:
 *                                           D <calls> <cycles> <min_call> <max_work> <pc>:<cycles>...
 *   W                                       the longest profiled call since the last W (or P), in
 *                                           cycles from its entry to its return: interrupt handlers
 *                                           and the H boundaries' calls included (how long the call
 *                                           held the main loop). Reply: W <cycles>
 *   Q                                       quit (reply: BYE)
 *
 * UART0 receive. simavr 1.6 queues input bytes in its own 64-byte FIFO at its own pace, so neither
 * its timing nor its DOR0 is the hardware's. The harness models the receiver instead: host bytes
 * occupy the line for 10 bit times each (16e6 * 10 / 115200 cycles); a byte is complete in the shift
 * register at its stop bit's middle and moves into the 2-byte receive FIFO if there is room (RXC0
 * set while the FIFO holds a byte, reading UDR0 pops it). Otherwise it waits in the shift register
 * and is lost when the next start bit arrives (an overrun: DOR0 is then set with the next byte that
 * enters the FIFO, as the datasheet says). UDR0 reads are served from this model.
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

/* UART0 receive model (header comment). Line times are in units of 1/9000 cycle: one bit at 115200
 * baud is 16e6 / 115200 = 1250/9 cycles, so without drift every edge is an exact integer, and a
 * --line-ppb drift (the host's bit time in MCU cycles) has a resolution of 0.8 ppb. */
#define LINE_QUEUE 65536
#define UNITS 9000u
#define BIT_UNITS 1250000u
static uint64_t bit_u = BIT_UNITS;
#define BYTE_U (10u * bit_u)
#define STOP_MIDDLE_U (bit_u * 19u / 2u) /* start + 8 data bits + half the stop bit */
static avr_uart_t* uart0;
static uint8_t line_byte[LINE_QUEUE];
static uint64_t line_start_u[LINE_QUEUE];
static size_t line_head, line_count;
static int line_head_started;       /* the head byte's start bit has reached the receiver */
static uint64_t line_free_u;         /* when the line can carry the next queued byte's start bit */
static int shift_full;              /* a complete byte waits in the shift register: the FIFO is full */
static uint8_t shift_byte;
static uint64_t shift_since;
static uint8_t fifo_byte[2], fifo_dor[2];
static uint64_t fifo_since[2];      /* the cycle the byte was complete: the latency's origin */
static int fifo_count;
static int dor_pending;             /* a byte was lost: the next byte into the FIFO carries DOR0 */
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

/* RXC0 and DOR0 follow the FIFO. The RX vector is sticky (RXC0 stays set while it runs), so it is
 * raised again while bytes remain: the handler runs once per byte, as on the hardware. */
static void rx_flags(void) {
    avr_regbit_setto(avr, uart0->dor, fifo_count > 0 && fifo_dor[0]);
    if (fifo_count > 0) {
        avr_raise_interrupt(avr, &uart0->rxc);
    } else {
        avr_clear_interrupt(avr, &uart0->rxc);
        avr_regbit_clear(avr, uart0->rxc.raised);
    }
}

static void fifo_push(uint8_t byte, uint64_t since) {
    fifo_byte[fifo_count] = byte;
    fifo_dor[fifo_count] = (uint8_t)dor_pending;
    fifo_since[fifo_count] = since;
    ++fifo_count;
    dor_pending = 0;
}

static uint8_t udr0_read(struct avr_t* a, avr_io_addr_t addr, void* param) {
    (void)param;
    if (fifo_count == 0) return a->data[addr]; /* nothing received: the last byte again */
    const uint8_t v = fifo_byte[0];
    const uint64_t latency = a->cycle - fifo_since[0];
    if (latency > rx_max_latency) rx_max_latency = latency;
    ++rx_bytes;
    fifo_byte[0] = fifo_byte[1];
    fifo_dor[0] = fifo_dor[1];
    fifo_since[0] = fifo_since[1];
    --fifo_count;
    if (shift_full) {
        shift_full = 0;
        fifo_push(shift_byte, shift_since);
    }
    rx_flags();
    return v;
}

static uint64_t ceil_u(uint64_t t) { return (t + UNITS - 1u) / UNITS; }

/* Every line edge due by now: start bits (a byte still in the shift register is lost) and stop bits
 * (the byte is complete). Returns the cycle of the next edge, 0 when the line is idle. */
static avr_cycle_count_t line_events(struct avr_t* a, avr_cycle_count_t when, void* param) {
    (void)when;
    (void)param;
    const uint64_t now_u = a->cycle * UNITS;
    const int rxen = (a->data[uart0->rxen.reg] >> uart0->rxen.bit) & 1;
    while (line_count > 0) {
        const uint64_t start_u = line_start_u[line_head];
        if (!line_head_started) {
            if (start_u > now_u) return ceil_u(start_u);
            line_head_started = 1;
            if (shift_full) {
                shift_full = 0;
                ++rx_overruns;
                dor_pending = 1;
            }
        }
        const uint64_t done_u = start_u + STOP_MIDDLE_U;
        if (done_u > now_u) return ceil_u(done_u);
        const uint8_t byte = line_byte[line_head];
        line_head = (line_head + 1) % LINE_QUEUE;
        --line_count;
        line_head_started = 0;
        if (!rxen) continue; /* receiver off (before Serial.begin): the byte is not received */
        if (fifo_count < 2) {
            fifo_push(byte, ceil_u(done_u));
            rx_flags();
        } else {
            shift_full = 1;
            shift_byte = byte;
            shift_since = ceil_u(done_u);
        }
    }
    return 0;
}

static int line_send(uint8_t byte) {
    if (line_count == LINE_QUEUE) return 0;
    const uint64_t now_u = avr->cycle * UNITS;
    const uint64_t start_u = line_free_u > now_u ? line_free_u : now_u;
    const size_t at = (line_head + line_count) % LINE_QUEUE;
    line_byte[at] = byte;
    line_start_u[at] = start_u;
    ++line_count;
    line_free_u = start_u + BYTE_U;
    return 1;
}

static void line_schedule(void) {
    if (line_count == 0) return;
    const uint64_t start_u = line_start_u[line_head];
    const uint64_t next_u = line_head_started ? start_u + STOP_MIDDLE_U : start_u;
    const uint64_t next = ceil_u(next_u);
    avr_cycle_timer_register(avr, next > avr->cycle ? next - avr->cycle : 0, line_events, NULL);
}

/* After a reset: the line and the receiver start empty. simavr refuses a second reader for UDR0
 * (avr_register_io_read aborts), so the model's reader replaces the UART module's in the I/O table;
 * simavr's own input FIFO is never fed. */
static void uart_rx_reset(void) {
    for (avr_io_t* io = avr->io_port; io != NULL && uart0 == NULL; io = io->next) {
        if (strcmp(io->kind, "uart") == 0 && ((avr_uart_t*)io)->name == '0') uart0 = (avr_uart_t*)io;
    }
    if (uart0 == NULL) {
        fprintf(stderr, "fil_harness: no UART0\n");
        exit(2);
    }
    avr->io[AVR_DATA_TO_IO(uart0->r_udr)].r.c = udr0_read;
    avr->io[AVR_DATA_TO_IO(uart0->r_udr)].r.param = NULL;
    avr_cycle_timer_cancel(avr, line_events, NULL);
    line_head = line_count = 0;
    line_head_started = 0;
    line_free_u = avr->cycle * UNITS;
    shift_full = 0;
    fifo_count = 0;
    dor_pending = 0;
}

/* Profile of one function's calls (P / D): cycles per PC inside its dynamic extent, interrupt
 * handlers excluded. One slot per flash word. A call counts when it returns (its cycles wait in
 * prof_cur until then), so a dump holds whole calls only. */
static avr_flashaddr_t prof_func;
static uint64_t *prof_hist, *prof_cur;
static uint32_t* prof_touched;
static size_t prof_words, prof_touched_count;
static int prof_in;
static uint16_t prof_sp;
static uint64_t prof_calls, prof_cycles, prof_call, prof_min = UINT64_MAX;
/* The current call's cycles inside handlers, and the most any call spent outside them. */
static uint64_t prof_call_handling, prof_max_work;
/* The current call's first cycle, and the longest call from entry to return (W). */
static uint64_t prof_entry, prof_max_span;
/* Handler boundaries (H): one histogram slot per flash word beyond prof_words for their cycles. */
#define PROF_HANDLER_FLAG 0x1000000u
#define PROF_MAX_HANDLERS 16
static avr_flashaddr_t prof_handlers[PROF_MAX_HANDLERS];
static int prof_handler_count, prof_in_handler;
static uint16_t prof_handler_sp;

static int prof_is_handler(avr_flashaddr_t pc) {
    for (int i = 0; i < prof_handler_count; ++i) {
        if (prof_handlers[i] == pc) return 1;
    }
    return 0;
}

static uint16_t sp(void) { return (uint16_t)(avr->data[R_SPL] | (avr->data[R_SPH] << 8)); }

static void prof_reset(void) {
    if (prof_hist != NULL) memset(prof_hist, 0, 2 * prof_words * sizeof *prof_hist);
    prof_calls = prof_cycles = prof_max_work = 0;
    prof_min = UINT64_MAX;
}

static void prof_abandon(void) { /* a call cut short by a reset or a new P */
    for (size_t i = 0; i < prof_touched_count; ++i) prof_cur[prof_touched[i]] = 0;
    prof_touched_count = 0;
    prof_in = 0;
    prof_in_handler = 0;
}

static int prof_alloc(void) {
    prof_words = (size_t)avr->flashend / 2 + 1;
    prof_hist = calloc(2 * prof_words, sizeof *prof_hist);
    prof_cur = calloc(2 * prof_words, sizeof *prof_cur);
    prof_touched = calloc(2 * prof_words, sizeof *prof_touched);
    return prof_hist != NULL && prof_cur != NULL && prof_touched != NULL;
}

static void prof_add(avr_flashaddr_t pc, uint64_t cycles) {
    const uint32_t w = (uint32_t)(pc >> 1) + (prof_in_handler ? (uint32_t)prof_words : 0u);
    if (prof_cur[w] == 0) prof_touched[prof_touched_count++] = w;
    prof_cur[w] += cycles;
    prof_call += cycles;
    if (prof_in_handler) prof_call_handling += cycles;
}

static void prof_return(void) {
    for (size_t i = 0; i < prof_touched_count; ++i) {
        const uint32_t w = prof_touched[i];
        prof_hist[w] += prof_cur[w];
        prof_cur[w] = 0;
    }
    prof_touched_count = 0;
    prof_in = 0;
    prof_in_handler = 0;
    ++prof_calls;
    prof_cycles += prof_call;
    if (prof_call < prof_min) prof_min = prof_call;
    if (prof_call - prof_call_handling > prof_max_work) prof_max_work = prof_call - prof_call_handling;
    if (avr->cycle - prof_entry > prof_max_span) prof_max_span = avr->cycle - prof_entry;
}

static void prof_dump(void) {
    printf("D %" PRIu64 " %" PRIu64 " %" PRIu64 " %" PRIu64, prof_calls, prof_cycles, prof_calls ? prof_min : 0,
           prof_max_work);
    int any = 0;
    for (size_t w = 0; prof_hist != NULL && w < 2 * prof_words; ++w) {
        if (prof_hist[w] == 0) continue;
        const size_t address = w < prof_words ? w * 2 : (w - prof_words) * 2 + PROF_HANDLER_FLAG;
        printf(" %zx:%" PRIu64, address, prof_hist[w]);
        any = 1;
    }
    printf(any ? "\n" : " -\n");
    prof_reset();
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
        /* The step's cycles belong to the instruction at the PC before it (an interrupt is entered
         * after the instruction, within the same avr_run). */
        const avr_flashaddr_t pc = avr->pc;
        const avr_cycle_count_t before = avr->cycle;
        const int in_isr = avr->interrupts.running_ptr > 0;
        if (prof_func != 0 && !prof_in && pc == prof_func && !in_isr) {
            prof_in = 1;
            prof_sp = sp();
            prof_entry = before;
            prof_call = 0;
            prof_call_handling = 0;
        } else if (prof_in && !prof_in_handler && !in_isr && prof_is_handler(pc)) {
            prof_in_handler = 1;
            prof_handler_sp = sp();
        }
        const int state = avr_run(avr);
        if (state == cpu_Done || state == cpu_Crashed) {
            fprintf(stderr, "fil_harness: the firmware stopped (state %d) at cycle %" PRIu64 "\n", state,
                    (uint64_t)avr->cycle);
            return 0;
        }
        if (prof_in) {
            if (!in_isr) prof_add(pc, avr->cycle - before);
            if (prof_in_handler && sp() > prof_handler_sp) prof_in_handler = 0;
            if (sp() > prof_sp) prof_return(); /* an interrupt lowers SP; only the return raises it */
        }
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
        for (size_t i = 0; tok[i] && tok[i + 1]; i += 2) {
            const int hi = hexval(tok[i]), lo = hexval(tok[i + 1]);
            if (hi < 0 || lo < 0 || !line_send((uint8_t)(hi * 16 + lo))) return 0;
        }
        line_schedule();
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
    uart_rx_reset();
    if (prof_in) prof_abandon();
}

/* The command-line options (argv[3..]): encoders, watched addresses, PCINT2 on port K, the ADC0
 * level and the line's drift. 0 when they parse, else the exit status. */
static int parse_options(int argc, char** argv, uint32_t* adc_mv) {
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
            *adc_mv = (uint32_t)strtoul(argv[++i], NULL, 0);
        } else if (strcmp(argv[i], "--line-ppb") == 0 && i + 1 < argc) {
            const long long ppb = strtoll(argv[++i], NULL, 0);
            if (ppb <= -100000000LL || ppb >= 100000000LL) {
                fprintf(stderr, "fil_harness: --line-ppb %lld is outside +-1e8 (10 %%)\n", ppb);
                return 2;
            }
            bit_u = (uint64_t)(((long long)BIT_UNITS * (1000000000LL + ppb) + 500000000LL) / 1000000000LL);
        } else {
            fprintf(stderr, "fil_harness: bad argument %s\n", argv[i]);
            return 2;
        }
    }
    return 0;
}

/* The MCU of that name with the ELF loaded, the encoders and the UART wired, after its reset.
 * 0 on success, else the exit status. */
static int load_mcu(const char* mmcu, const char* elf, uint32_t adc_mv, char* loaded_mmcu, size_t loaded_size) {
    elf_firmware_t fw;
    memset(&fw, 0, sizeof fw);
    if (elf_read_firmware(elf, &fw) != 0) {
        fprintf(stderr, "fil_harness: cannot read %s\n", elf);
        return 2;
    }
    strncpy(fw.mmcu, mmcu, sizeof fw.mmcu - 1);
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
    snprintf(loaded_mmcu, loaded_size, "%s", fw.mmcu);
    return 0;
}

/* One command per line on stdin, one answer line each on stdout, until Q or the end of input: one
 * switch with a case per command of the line protocol, which is why it runs long. */
static int serve_commands(uint32_t adc_mv) {
    static char line[MAX_LINE];
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
            case 'P':
                if (prof_hist == NULL && !prof_alloc()) {
                    ok = 0;
                    break;
                }
                prof_func = (avr_flashaddr_t)strtoul(line + 1, NULL, 0);
                if (prof_in) prof_abandon();
                prof_reset();
                prof_max_span = 0;
                printf("OK\n");
                break;
            case 'H': {
                const avr_flashaddr_t address = (avr_flashaddr_t)strtoul(line + 1, NULL, 0);
                if (address == 0) {
                    prof_handler_count = 0;
                } else if (prof_handler_count < PROF_MAX_HANDLERS) {
                    prof_handlers[prof_handler_count++] = address;
                } else {
                    ok = 0;
                    break;
                }
                printf("OK\n");
                break;
            }
            case 'D':
                prof_dump();
                break;
            case 'W':
                printf("W %" PRIu64 "\n", prof_max_span);
                prof_max_span = 0;
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


int main(int argc, char** argv) {
    if (argc < 3) {
        fprintf(stderr, "usage: %s MCU ELF [--enc PA PB]... [--pcint-k] [--watch ADDR]... [--adc0 MV] [--line-ppb N]\n",
                argv[0]);
        return 2;
    }
    uint32_t adc_mv = 1234;
    int status = parse_options(argc, argv, &adc_mv);
    char mmcu[sizeof ((elf_firmware_t*)0)->mmcu];
    if (status == 0) status = load_mcu(argv[1], argv[2], adc_mv, mmcu, sizeof mmcu);
    if (status != 0) return status;
    setvbuf(stdout, NULL, _IOFBF, 1 << 16);
    printf("READY %s\n", mmcu); /* simavr's loader prints to stdout before this: skip to here */
    fflush(stdout);
    return serve_commands(adc_mv);
}
