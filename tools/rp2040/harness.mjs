// The firmware-in-the-loop harness for the RP2040: an SRAM image in rp2040js, stepped by
// emulator/backends/rp2040/harness.py with the step protocol of the simavr harness.
//
//   node tools/rp2040/harness.mjs IMAGE.bin [--flash] [--enc A B]... [--watch PIN]... [--baud N] [--seed N]
//                                 [--histogram]
//
// --histogram: the cycles executed at every PC, which P reports (a profile: benchmarks/rp2040.py
// maps the PCs to source files).
//
// IMAGE.bin is an SRAM image started at its vector table, or with --flash the image a Pico runs
// from flash: its 256-byte boot block is checked (CRC-32) and run from SRAM as the boot ROM does
// (rp2040js has no boot ROM), and the block starts the image through its vector table.
//
// One request per line on stdin, one reply per line on stdout:
//
//   S US C1 C2 .. RXHEX   run US microseconds of the chip's time. Ck is encoder k's position in
//                         counts: each change becomes quadrature edges on its two pins, spread
//                         evenly over the step; RXHEX (or -) are the host's bytes for UART0, sent
//                         at the baud rate from the start of the step (those that do not fit wait
//                         for the next). Reply: OK NANOS PINS TXHEX, where PINS is, per watched
//                         pin, HIGH_PPM:LEVEL:PULSE_NS (the part of the step it was high, its
//                         level at the end, the high time its PWM slice is set to, or 0)
//                         joined by commas, and TXHEX the bytes UART0 put on the line by the
//                         end of the step, paced at the baud rate (or -).
//   R                     reset: a new chip, every peripheral in its reset state, running the image
//                         again (what the board's reset does); the clock goes on.
//   H                     hang: the core stops executing (a firmware stuck in a loop, with its
//                         interrupts off) while the peripherals and the watchdog go on; the next
//                         reset (R, or the watchdog's) ends it.
//   P                     the histogram: OK PC:CYCLES,PC:CYCLES.. (hex PCs), or OK - without one
//   N                     resets so far (a watchdog's among them): OK COUNT
//   C                     cycles the core has executed (not asleep) since the harness started: OK BUSY
//   Q                     quit.
//
// Time is the simulation clock's (ns); the core runs 125 MHz cycles and sleeps through WFI up to
// the next event (a timer alarm, a PWM edge, an encoder edge or a received byte). The ring
// oscillator's random bit, which rp2040js lacks, comes from a generator seeded with --seed.
import { readFileSync } from 'node:fs';
import { createInterface } from 'node:readline';
import { BasePeripheral, RP2040 } from 'rp2040js';

const CYCLE_NS = 8; // 125 MHz
const ROSC_BASE = 0x40060;
const ROSC_RANDOMBIT = 0x1c;

/** The ring oscillator as firmware reads its noise (RANDOMBIT, datasheet 2.17.5), which rp2040js
 * leaves unimplemented: a bit from a generator seeded with --seed, fresh on every read and going
 * on across resets (a second boot draws other bits). */
class RingOscillator extends BasePeripheral {
  constructor(mcu, noise) {
    super(mcu, 'ROSC_BASE');
    this.noise = noise;
  }
  readUint32(offset) {
    return offset === ROSC_RANDOMBIT ? this.noise.bit() : 0;
  }
  writeUint32() {}
}

/** xorshift32: the jitter of a real ring oscillator, repeatable for a given seed. */
class Noise {
  constructor(seed) {
    this.state = seed >>> 0 || 1;
  }
  bit() {
    this.state ^= this.state << 13;
    this.state ^= this.state >>> 17;
    this.state ^= this.state << 5;
    this.state >>>= 0;
    return this.state >>> 31;
  }
}

const SRAM = 0x20000000;
const GPIO_FUNC_PWM = 4;
const BOOT2_SRAM = 0x20041f00; // where the boot ROM copies the boot block
const BOOT2_BYTES = 256;

/** The boot ROM's CRC-32 of the boot block (CRC-32/MPEG-2: not reflected, no final XOR). */
function crc32Mpeg2(bytes) {
  let crc = 0xffffffff;
  for (const byte of bytes) {
    crc ^= byte << 24;
    for (let i = 0; i < 8; i++) crc = crc & 0x80000000 ? (crc << 1) ^ 0x04c11db7 : crc << 1;
    crc >>>= 0;
  }
  return crc >>> 0;
}
const QUADRATURE = [
  [false, false],
  [true, false],
  [true, true],
  [false, true],
];

function parseArgs(argv) {
  const args = { image: argv[0], flash: false, encoders: [], watch: [], baud: 115200, seed: 1, histogram: false };
  for (let i = 1; i < argv.length; i++) {
    if (argv[i] === '--flash') args.flash = true;
    else if (argv[i] === '--enc') args.encoders.push([Number(argv[++i]), Number(argv[++i])]);
    else if (argv[i] === '--watch') args.watch.push(Number(argv[++i]));
    else if (argv[i] === '--baud') args.baud = Number(argv[++i]);
    else if (argv[i] === '--seed') args.seed = Number(argv[++i]);
    else if (argv[i] === '--histogram') args.histogram = true;
    else throw new Error(`unknown argument ${argv[i]}`);
  }
  if (!args.image) throw new Error('usage: harness.mjs IMAGE.bin [--enc A B]... [--watch PIN]... [--baud N] [--seed N]');
  return args;
}

class Harness {
  constructor(args) {
    this.args = args;
    this.image = readFileSync(args.image);
    this.resets = 0;
    this.rxQueue = [];
    this.byteNs = Math.round(10e9 / args.baud); // start bit, 8 data bits, stop bit
    this.busy = 0;
    this.histogram = args.histogram ? new Map() : null;
    this.positions = args.encoders.map(() => 0);
    this.noise = new Noise(args.seed);
    this.base = 0; // ns before the current chip's clock started (each reset makes a new chip)
    this.high = args.watch.map(() => 0);
    this.since = args.watch.map(() => 0);
    if (args.flash) {
      const block = this.image.subarray(0, BOOT2_BYTES);
      const stored = new DataView(block.buffer, block.byteOffset + 252, 4).getUint32(0, true);
      if (block.length < BOOT2_BYTES || crc32Mpeg2(block.subarray(0, 252)) !== stored) {
        throw new Error('the boot block (first 256 bytes) fails its CRC-32: the boot ROM would not run it');
      }
    }
    this.boot();
  }

  /** A new chip, as a reset leaves one (every peripheral in its reset state), running the image. */
  boot() {
    if (this.mcu) this.base += this.mcu.clock.nanos;
    this.hung = false;
    const mcu = new RP2040();
    this.mcu = mcu;
    // rp2040js hands over each byte as it is written: the line takes it at the baud rate, after
    // the bytes before it (the chip's FIFO never fills here, so the firmware never waits on it).
    this.tx = [];
    this.txFree = this.nanos;
    mcu.uart[0].onByte = (b) => {
      this.txFree = Math.max(this.nanos, this.txFree) + this.byteNs;
      this.tx.push([this.txFree, b]);
    };
    // WATCHDOG_BASE. A trigger stops this chip's watchdog (rp2040js would fire it again and again
    // at the same instant while the old chip's clock finishes its tick) and starts a new chip.
    const watchdog = mcu.peripherals[0x40058];
    watchdog.onWatchdogTrigger = () => {
      watchdog.alarm.enable = false;
      watchdog.timer.enable = false;
      if (this.mcu === mcu) this.reset();
    };
    mcu.peripherals[ROSC_BASE] = new RingOscillator(mcu, this.noise);
    for (const [k, pin] of this.args.watch.entries()) {
      mcu.gpio[pin].addListener(() => this.pinChanged(k));
    }
    const { image } = this;
    if (this.args.flash) {
      // The boot ROM's last steps: the boot block copied to SRAM and called with lr = 0.
      mcu.flash.set(image, 0);
      mcu.sram.set(image.subarray(0, BOOT2_BYTES), BOOT2_SRAM - SRAM);
      mcu.core.SP = BOOT2_SRAM + BOOT2_BYTES;
      mcu.core.LR = 0;
      mcu.core.PC = BOOT2_SRAM;
    } else {
      mcu.sram.set(image, 0);
      const view = new DataView(image.buffer, image.byteOffset, image.byteLength);
      mcu.core.SP = view.getUint32(0, true);
      mcu.core.PC = view.getUint32(4, true) & ~1;
      mcu.core.VTOR = SRAM;
    }
    for (const [k, [a, b]] of this.args.encoders.entries()) this.drive(k, a, b, true);
  }

  reset() {
    this.resets += 1;
    this.boot();
  }

  /** Sets encoder k's pins to its position's quadrature state: only a pin that changes, since
   * rp2040js latches an edge on every setInputValue, changed or not (a real pin sees none). */
  drive(k, a, b, boot = false) {
    const [va, vb] = QUADRATURE[((this.positions[k] % 4) + 4) % 4];
    for (const [pin, value] of [
      [a, va],
      [b, vb],
    ]) {
      if (boot || this.mcu.gpio[pin].inputValue !== value) this.mcu.gpio[pin].setInputValue(value);
    }
  }

  get nanos() {
    return this.base + this.mcu.clock.nanos;
  }

  pinChanged(k) {
    const pin = this.mcu.gpio[this.args.watch[k]];
    // The level before this change held since `since`: a rising edge ends a low stretch.
    if (!pin.outputValue) this.high[k] += this.nanos - this.since[k];
    this.since[k] = this.nanos;
  }

  /** Runs the core until `until` (ns), sleeping through WFI up to the next alarm or `until`. */
  runUntil(until) {
    while (this.nanos < until) {
      const { mcu } = this; // a new chip after a watchdog reset inside the loop
      const clock = mcu.clock;
      if (mcu.core.waiting || this.hung) {
        // Asleep (WFI) or hung: on to the next alarm (none scheduled: to `until`).
        const left = until - this.nanos;
        const next = clock.nextAlarm ? clock.nanosToNextAlarm : left;
        clock.tick(Math.max(0, Math.min(next, left)));
      } else {
        const pc = mcu.core.PC;
        const cycles = mcu.core.executeInstruction();
        this.busy += cycles;
        if (this.histogram) this.histogram.set(pc, (this.histogram.get(pc) ?? 0) + cycles);
        clock.tick(cycles * CYCLE_NS);
      }
    }
  }

  /** The high time per period `pin`'s PWM slice is set to (its channel's compare value in
   * counter ticks of clk_sys / divider), 0 when the pin is not on a running slice: the width the
   * firmware set, as the simavr harness reads a timer's compare register (a new value reaches
   * the pin at the slice's next wrap). */
  pulseNs(pin) {
    const gpio = this.mcu.gpio[pin];
    const slice = this.mcu.pwm.channels[(pin >> 1) & 7];
    if (gpio.functionSelect !== GPIO_FUNC_PWM || !(slice.csr & 1)) return 0;
    const level = pin & 1 ? slice.cc >>> 16 : slice.cc & 0xffff;
    return Math.round((level * CYCLE_NS * slice.div) / 16); // DIV: 8.4 fixed point
  }

  step(us, counts, rx) {
    const start = this.nanos;
    const end = start + us * 1000;
    for (let k = 0; k < this.args.watch.length; k++) {
      this.high[k] = 0;
      this.since[k] = start;
    }
    this.rxQueue.push(...rx);
    const events = [];
    const { byteNs } = this;
    for (let i = 0; i < this.rxQueue.length && start + (i + 1) * byteNs <= end; i++) {
      const byte = this.rxQueue[i];
      events.push([start + (i + 1) * byteNs, () => this.mcu.uart[0].feedByte(byte)]);
    }
    const fed = events.length;
    for (const [k, [a, b]] of this.args.encoders.entries()) {
      const delta = (counts[k] ?? this.positions[k]) - this.positions[k];
      const n = Math.abs(delta);
      for (let i = 1; i <= n; i++) {
        events.push([
          start + Math.round((i * (end - start)) / (n + 1)),
          () => {
            this.positions[k] += Math.sign(delta);
            this.drive(k, a, b);
          },
        ]);
      }
    }
    events.sort((x, y) => x[0] - y[0]);
    for (const [at, act] of events) {
      this.runUntil(at);
      act();
    }
    this.runUntil(end);
    this.rxQueue.splice(0, fed);
    const pins = this.args.watch.map((pin, k) => {
      const level = this.mcu.gpio[pin].outputValue;
      const high = this.high[k] + (level ? end - this.since[k] : 0);
      return `${Math.round((high * 1e6) / (end - start))}:${level ? 1 : 0}:${this.pulseNs(pin)}`;
    });
    // The bytes whose stop bit has left by the end of the step; the rest go with later steps.
    const sent = this.tx.findIndex(([at]) => at > end);
    const out = this.tx.splice(0, sent < 0 ? this.tx.length : sent).map(([, b]) => b);
    const tx = Buffer.from(out).toString('hex') || '-';
    return `OK ${this.nanos} ${pins.join(',') || '-'} ${tx}`;
  }
}

const harness = new Harness(parseArgs(process.argv.slice(2)));
const lines = createInterface({ input: process.stdin });
process.stdout.write('READY\n');
for await (const line of lines) {
  const [command, ...rest] = line.trim().split(/\s+/);
  let reply;
  try {
    if (command === 'S') {
      const us = Number(rest[0]);
      const rxHex = rest[rest.length - 1];
      const counts = rest.slice(1, -1).map(Number);
      reply = harness.step(us, counts, rxHex === '-' ? [] : [...Buffer.from(rxHex, 'hex')]);
    } else if (command === 'R') {
      harness.reset();
      reply = 'OK';
    } else if (command === 'H') {
      harness.hung = true;
      reply = 'OK';
    } else if (command === 'P') {
      const h = harness.histogram;
      reply = h && h.size ? `OK ${[...h].map(([pc, c]) => `${pc.toString(16)}:${c}`).join(',')}` : 'OK -';
    } else if (command === 'C') {
      reply = `OK ${harness.busy}`;
    } else if (command === 'N') {
      reply = `OK ${harness.resets}`;
    } else if (command === 'Q') {
      process.stdout.write('OK\n');
      process.exit(0);
    } else {
      reply = 'ERR unknown command';
    }
  } catch (error) {
    reply = `ERR ${String(error).replace(/\s+/g, ' ')}`;
  }
  process.stdout.write(`${reply}\n`);
}
