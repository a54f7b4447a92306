"""Budgets measured on the real binary: every example's ELF in simavr (cycle counts) and avr-size.

    python3 benchmarks/firmware.py            # all examples, print the figures, the budgets and where
                                              # the decode and dispatch cycles go
    python3 benchmarks/firmware.py --json     # machine-readable

Method. Two instruments in the harness (tools/simavr/fil_harness.c):

* a loop marker counts the passes of the sketch's main loop (each pass calls serialEventRun()
  once, a symbol the ELF keeps). The shortest pass is poll() with nothing to do; every cycle beyond
  `passes x shortest` is work: control ticks, frames, interrupts;
* a profiler follows the calls of `roverlink::Session<App>::poll()` (the function that reads the
  bytes waiting in the serial port, feeds the frame decoder and dispatches every complete frame,
  reply included): from the PC reaching its address until SP rises above its value there, each
  instruction's cycles are added to its PC, interrupt handlers excluded. avr-addr2line maps the
  PCs to source files (the ELF is built with -g); PCs without line information (libgcc's soft
  float and prologue helpers, which LTO's line tables attribute to main) are named by avr-nm's
  symbol.

Figures (docs/budgets.md states the budgets and why they are per byte):

* Frame decoder cycles per byte (budget <= 86: at most 1/2.5 of SerialTransfer's parse(), 214.8
  cycles per byte, measured in simavr on the Uno with the Arduino IDE's flags: 4,726 cycles for a
  22-byte packet, the per-byte costs 169/191/191/197/202x15/210/514/224): the cycles inside
  Session::poll() whose source is the decoder's (frame_decoder.cpp/.h, crc16.cpp/.h and the
  generated proto::message_bounds(): COBS undone byte by byte, the length, id and CRC checks, the
  decoder's counters) while SET_PID frames arrive back to back, divided by the bytes of those
  frames. The ratio printed is 214.8 / that figure.
* Read, decode and dispatch cycles per byte of frame (budget <= 120): the cycles inside
  Session::poll while the host sends SET_PID frames (21-byte payload, 27 bytes on the wire, the
  command nearest the 16-byte payload the anchor was measured with) back to back at 115200 baud
  for 1 s, less the instructions whose source is the Arduino core's serial driver
  (HardwareSerial*.cpp/.h, Print, Stream, and what is inlined into their functions, e.g.
  ATOMIC_BLOCK: reading the ring buffer, writing the reply into the TX buffer), less `calls x the
  cheapest call` (poll() finding no byte: measured over 20 ms with no host bytes, where every call
  takes that path, with the same source filter), less the handling (below), divided by the bytes
  sent. Counted: reading the bytes from the Stream, COBS decoding, CRC, length and id checks,
  unpacking and range checks, the session rules (seq, watchdog, duplicate detection, state
  table), libgcc helpers called from there (prologues). Not counted: interrupt handlers (RX and TX
  of every byte, timers, encoders), the serial driver, control ticks (outside poll()). Every frame
  must be answered (SET_PID: one ACK each) or the run is invalid. SET_WHEEL_SPEEDS /
  SET_ACKERMANN (4-byte payload, sent 100 times a second, no reply in STREAM mode) are reported per
  frame and per byte too: their fixed per-frame work is spread over 10 bytes.
* Handling and reply per command frame (reported beside it, no budget): the cycles inside poll()
  spent in calls of the App's code (roverlink::Firmware::*: SET_PID's gains applied, the session's
  actions on the motors) and of the reply's sending (SessionCore::send_answer, Link::send_payload:
  packing, CRC and COBS of the ACK), which the harness keeps apart (its H command). Decode +
  dispatch + handling is what the whole frame costs inside poll().
* The longest poll() (budget: POLL_SPAN_BUDGET_CYCLES, 5 % of the 10 ms control period): the
  longest single call in the SET_PID flood from its entry to its return, handling, reply and
  interrupts included (the harness's W command): the control tick is checked between poll() calls,
  so this is the most one call delays a tick. A call reads every byte waiting up to the end of one
  frame, so after a control tick it takes most of a frame at once. Why 5 %: ticks stay on a fixed
  grid and the speed measurement divides by the nominal period, so a tick d late reads its wheel
  speeds d/10 ms high and the next one as much low, nothing accumulating; 5 % is about one encoder
  count per tick at 300 mm/s on the finest reference encoder (12.9 mm/s, 4.3 %), the
  measurement's own resolution. The same call less its handlers (decoding and dispatching alone)
  is reported too.
* Full cost per command frame (no budget; what a frame really costs the CPU): the main-loop work
  during the same floods less the work of ticks and FEEDBACK (measured over 1 s of driving),
  divided by the frames sent: decode and dispatch plus the RX interrupt of every byte, the serial
  driver's reads, and the reply's TX interrupts.
* CPU share of the 100 Hz control loop: work / cycles over 2 s with a session open, armed and
  driving (one setpoint per tick, FEEDBACK streaming at the configured rate), less the full cost
  of the setpoint frames themselves. Gated at 50 % of the CPU.
* Receive overruns and latency while frames arrive back to back (both floods): the harness models
  the ATmega's receiver (a shift register and a 2-byte FIFO; a byte still in the shift register
  when the next start bit arrives is lost and DOR0 set), so an overrun here is one on the
  hardware. Gated at 0. Also the longest time from a byte's stop bit to the RX interrupt reading
  it from UDR0 (gated at two byte times, 2 x 1389 cycles) and the longest main-loop pass (a byte
  that arrives just after poll() emptied the buffer waits one pass; the Arduino core's 64-byte ring
  buffer holds 5.5 ms of bytes at 115200 baud).
* Flash and SRAM per example: avr-size of the ELF (`roverlink.firmware`); a reference firmware on
  the Uno leaves >= 50 % of flash and SRAM free.
* Line use (budget <= 40 % of either direction): 100 Hz setpoints and 100 Hz FEEDBACK at 115200
  baud, from the frames' sizes (line_use.py; no simulation needed).

`python3 benchmarks/firmware.py` exits 0 when every budget holds, else 1 with one OVER BUDGET line
per failure, naming it.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import time
from collections import defaultdict
from dataclasses import asdict, dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import line_use  # noqa: E402
from avr_sources import Source, function_lines, short, sources  # noqa: E402
from firmware_run import LoopStats, Profile, Run, exercise, setpoint  # noqa: E402

from emulator.backends.simavr import HANDLER_FLAG, SimavrRobot  # noqa: E402
from protocol.generated.constants import CONTROL_RATE_HZ  # noqa: E402
from protocol.generated.profiles import PROFILES  # noqa: E402
from roverlink import firmware  # noqa: E402

CPU_HZ = 16_000_000
CYCLES_PER_BYTE = CPU_HZ * 10 // 115_200  # 1388 (1388.9)
SERIALTRANSFER_CYCLES_PER_BYTE = 4726 / 22  # 214.8: the anchor (docstring, docs/budgets.md)
SERIALTRANSFER_PACKET_CYCLES_PER_BYTE = 302.8  # its whole packet: read, parse() and unpack
DECODER_RATIO_BUDGET = 2.5
DECODER_CYCLES_PER_BYTE_BUDGET = 86  # SERIALTRANSFER_CYCLES_PER_BYTE / DECODER_RATIO_BUDGET = 85.9
FRAME_CYCLES_PER_BYTE_BUDGET = 120
CONTROL_PERIOD_CYCLES = CPU_HZ // CONTROL_RATE_HZ
POLL_SPAN_BUDGET_CYCLES = CONTROL_PERIOD_CYCLES * 5 // 100  # 8,000 cycles, 500 us
CONTROL_SHARE_BUDGET = 0.50
UNO_FREE_FRACTION = 0.50
SERIAL_DRIVER_FILE = re.compile(r"^(HardwareSerial\w*|Print|Stream)\.(cpp|h)$")
SERIAL_DRIVER_FUNCTION = re.compile(r"^(HardwareSerial|Print|Stream)::")
# The frame decoder's code, by the innermost source of an instruction (LTO keeps the inlined
# code's file and line, not its function): its files, and the generated msg_id lookup it calls.
DECODER_FILES = re.compile(r"^(frame_decoder|crc16)\.(cpp|h)$")
GENERATED_SOURCE = ROOT / "arduino" / "RoverLink" / "src" / "generated" / "roverlink_protocol.cpp"


@dataclass
class Figures:
    example: str
    board: str
    flash_bytes: int
    flash_capacity: int
    sram_bytes: int
    sram_capacity: int
    control_cpu_share: float
    set_pid_frame_bytes: int
    setpoint_frame_bytes: int
    decoder_cycles_per_byte: float
    """The frame decoder's cycles (DECODER_FUNCTIONS) per byte of SET_PID frame."""
    decode_dispatch_cycles_per_set_pid_frame: float
    decode_dispatch_cycles_per_setpoint_frame: float
    handling_cycles_per_set_pid_frame: float
    handling_cycles_per_setpoint_frame: float
    full_cycles_per_set_pid_frame: float
    full_cycles_per_setpoint_frame: float
    poll_idle_call_cycles: int
    longest_set_pid_poll_cycles: int
    """The longest single poll() call in the SET_PID flood, handling and reply excluded: how long
    decoding and dispatching hold the loop in one go (serial driver reads included)."""
    longest_poll_span_cycles: int
    """The longest poll() call in the SET_PID flood from entry to return, handling, reply and
    interrupts included: the most one call delays a control tick."""
    worst_loop_pass_cycles: int
    worst_rx_isr_latency_cycles: int
    rx_bytes: int
    rx_overruns: int
    realtime_ratio: float
    line: line_use.LineUse
    set_pid_breakdown: dict[str, dict[str, float]] = field(default_factory=dict)
    """Cycles per SET_PID frame inside poll() by "file", "function" and "line" (handling included)."""
    setpoint_breakdown: dict[str, dict[str, float]] = field(default_factory=dict)
    """The same per setpoint frame."""


def decode_dispatch(
    flood: Profile, idle: Profile, frames: int, src: dict[int, Source]
) -> tuple[float, float, float, dict[str, dict[str, float]]]:
    """Cycles per frame inside poll(), serial driver excluded, less `calls x the cheapest call`
    (the idle window's per-call profile, filtered the same way): (decode and dispatch, handling,
    the frame decoder's share of decode and dispatch), and where they go. Handling is what ran
    inside the handler boundaries (firmware_run.HANDLER_SYMBOLS)."""
    if idle.calls == 0 or idle.cycles != idle.calls * idle.cheapest_call:
        raise SystemExit(f"BENCHMARK INVALID: the idle window's poll() calls differ ({idle})")
    groups: dict[str, dict[str, float]] = {"file": defaultdict(float), "function": defaultdict(float)}
    groups["line"] = defaultdict(float)
    totals = [0.0, 0.0]
    decoder = 0.0
    lookup = function_lines(GENERATED_SOURCE, "bool message_bounds(")
    for key in flood.per_pc.keys() | idle.per_pc.keys():
        handling = key >= HANDLER_FLAG
        s = src[key - HANDLER_FLAG if handling else key]
        if SERIAL_DRIVER_FILE.match(s.file) or SERIAL_DRIVER_FUNCTION.match(s.function):
            continue
        excess = (flood.per_pc.get(key, 0) - flood.calls * idle.per_pc.get(key, 0) / idle.calls) / frames
        totals[handling] += excess
        if not handling and (DECODER_FILES.match(s.file) or (s.file == GENERATED_SOURCE.name and s.line in lookup)):
            decoder += excess
        mark = " (handling)" if handling else ""
        groups["file"][s.file + mark] += excess
        groups["function"][short(s.function) + mark] += excess
        groups["line"][(f"{s.file}:{s.line}" if s.line else short(s.function)) + mark] += excess
    ordered = {k: dict(sorted(v.items(), key=lambda kv: -kv[1])) for k, v in groups.items()}
    return totals[0], totals[1], decoder, ordered


def _work(stats: LoopStats) -> int:
    passes, cycles, shortest, _ = stats
    return cycles - passes * shortest


def measure(example: str, profile: str) -> Figures:
    build = firmware.build_example(example, out_dir=ROOT / "build" / "simavr" / "elf" / example)
    wall0 = time.perf_counter()
    robot = SimavrRobot(profile, elf=build.elf)
    try:
        run = exercise(robot, build.elf, example, profile)
    finally:
        robot.close()
    return _figures(example, profile, build, run, realtime_ratio=run.sim_s / (time.perf_counter() - wall0))


def _figures(example: str, profile: str, build: firmware.BuildResult, run: Run, realtime_ratio: float) -> Figures:
    sp, pid = run.setpoints, run.set_pids
    per_cycle_tick_work = _work(run.base) / max(1, run.base[1])
    full_sp = (_work(sp.loop) - per_cycle_tick_work * sp.loop[1]) / sp.frames
    full_pid = (_work(pid.loop) - per_cycle_tick_work * pid.loop[1]) / pid.frames
    keys = run.idle.per_pc.keys() | sp.profile.per_pc.keys() | pid.profile.per_pc.keys()
    src = sources(build.elf, sorted({k - HANDLER_FLAG if k >= HANDLER_FLAG else k for k in keys}))
    dd_sp, handling_sp, _, sp_breakdown = decode_dispatch(sp.profile, run.idle, sp.frames, src)
    dd_pid, handling_pid, decoder_pid, pid_breakdown = decode_dispatch(pid.profile, run.idle, pid.frames, src)
    latency, rx_bytes, overruns = run.rx
    return Figures(
        example=example,
        board=build.board.name,
        flash_bytes=build.flash_used,
        flash_capacity=build.board.flash_bytes,
        sram_bytes=build.sram_used,
        sram_capacity=build.board.sram_bytes,
        control_cpu_share=(_work(run.driving) - run.ticks * full_sp) / max(1, run.driving[1]),
        set_pid_frame_bytes=pid.frame_bytes,
        setpoint_frame_bytes=sp.frame_bytes,
        decoder_cycles_per_byte=decoder_pid / pid.frame_bytes,
        decode_dispatch_cycles_per_set_pid_frame=dd_pid,
        decode_dispatch_cycles_per_setpoint_frame=dd_sp,
        handling_cycles_per_set_pid_frame=handling_pid,
        handling_cycles_per_setpoint_frame=handling_sp,
        full_cycles_per_set_pid_frame=full_pid,
        full_cycles_per_setpoint_frame=full_sp,
        poll_idle_call_cycles=run.idle.cheapest_call,
        longest_set_pid_poll_cycles=pid.profile.longest_work,
        longest_poll_span_cycles=pid.longest_call,
        worst_loop_pass_cycles=max(sp.loop[3], pid.loop[3]),
        worst_rx_isr_latency_cycles=latency,
        rx_bytes=rx_bytes,
        rx_overruns=overruns,
        realtime_ratio=realtime_ratio,
        set_pid_breakdown=pid_breakdown,
        setpoint_breakdown=sp_breakdown,
        line=line_use.line_use(type(setpoint(profile, 0))),
    )


def frame_cycles_per_byte(f: Figures) -> float:
    """Read, decode and dispatch cycles per byte of SET_PID frame (the budgeted figure)."""
    return f.decode_dispatch_cycles_per_set_pid_frame / f.set_pid_frame_bytes


def problems(f: Figures) -> list[str]:
    """One line per budget the example breaks, naming it; empty when every budget holds."""
    out = []
    if f.decoder_cycles_per_byte > DECODER_CYCLES_PER_BYTE_BUDGET:
        out.append(
            f"{f.example}: frame decoder {f.decoder_cycles_per_byte:.1f} cycles/byte > {DECODER_CYCLES_PER_BYTE_BUDGET}"
            f" (1/{DECODER_RATIO_BUDGET} of SerialTransfer's {SERIALTRANSFER_CYCLES_PER_BYTE:.1f})"
        )
    if frame_cycles_per_byte(f) > FRAME_CYCLES_PER_BYTE_BUDGET:
        out.append(
            f"{f.example}: read, decode and dispatch {frame_cycles_per_byte(f):.1f} cycles per byte of SET_PID frame"
            f" > {FRAME_CYCLES_PER_BYTE_BUDGET}"
        )
    if f.longest_poll_span_cycles > POLL_SPAN_BUDGET_CYCLES:
        out.append(
            f"{f.example}: the longest poll() call takes {f.longest_poll_span_cycles} cycles"
            f" > {POLL_SPAN_BUDGET_CYCLES} (5% of the control period: a control tick is delayed that long)"
        )
    if f.control_cpu_share > CONTROL_SHARE_BUDGET:
        out.append(f"{f.example}: control loop uses {f.control_cpu_share:.1%} of the CPU > {CONTROL_SHARE_BUDGET:.0%}")
    if f.worst_rx_isr_latency_cycles > 2 * CYCLES_PER_BYTE:
        out.append(f"{f.example}: RX latency {f.worst_rx_isr_latency_cycles} cycles > two byte times")
    if f.rx_overruns:
        out.append(f"{f.example}: {f.rx_overruns} bytes lost to receive overruns")
    if f.board == "uno":
        if f.flash_bytes > f.flash_capacity * UNO_FREE_FRACTION:
            out.append(f"{f.example}: flash {f.flash_bytes} B > 50% of {f.flash_capacity} B")
        if f.sram_bytes > f.sram_capacity * UNO_FREE_FRACTION:
            out.append(f"{f.example}: SRAM {f.sram_bytes} B > 50% of {f.sram_capacity} B")
    out += [f"{f.example}: {p}" for p in line_use.problems(f.line)]
    return out


def report(f: Figures) -> str:
    ratio = SERIALTRANSFER_CYCLES_PER_BYTE / f.decoder_cycles_per_byte
    per_byte_sp = f.decode_dispatch_cycles_per_setpoint_frame / f.setpoint_frame_bytes
    packet_ratio = SERIALTRANSFER_PACKET_CYCLES_PER_BYTE / frame_cycles_per_byte(f)
    return (
        f"{f.example} ({f.board}): flash {f.flash_bytes:,}/{f.flash_capacity:,} B, SRAM {f.sram_bytes:,}/"
        f"{f.sram_capacity:,} B; control loop {f.control_cpu_share:.1%} CPU\n"
        f"    frame decoder: {f.decoder_cycles_per_byte:.1f} cycles/byte (budget {DECODER_CYCLES_PER_BYTE_BUDGET}); "
        f"SerialTransfer's parse() {SERIALTRANSFER_CYCLES_PER_BYTE:.1f}: {ratio:.2f}x fewer "
        f"(budget {DECODER_RATIO_BUDGET}x)\n"
        f"    read+decode+dispatch (Session::poll up to the handler, no ISRs, no serial driver, less idle polls): "
        f"{frame_cycles_per_byte(f):.1f} cycles/byte of SET_PID frame (budget {FRAME_CYCLES_PER_BYTE_BUDGET}): "
        f"{f.decode_dispatch_cycles_per_set_pid_frame:.0f} cycles/{f.set_pid_frame_bytes}-byte frame; setpoint "
        f"{f.decode_dispatch_cycles_per_setpoint_frame:.0f} cycles/{f.setpoint_frame_bytes}-byte frame "
        f"({per_byte_sp:.1f}/byte); idle poll() {f.poll_idle_call_cycles} cycles; SerialTransfer's whole packet "
        f"{SERIALTRANSFER_PACKET_CYCLES_PER_BYTE}: {packet_ratio:.2f}x fewer\n"
        f"    + handling and reply (the App's code, the ACK): {f.handling_cycles_per_set_pid_frame:.0f} cycles/SET_PID "
        f"frame, {f.handling_cycles_per_setpoint_frame:.0f} cycles/setpoint frame\n"
        f"    full cost (+ RX ISR per byte, serial driver, reply TX ISRs): "
        f"{f.full_cycles_per_set_pid_frame:.0f} cycles/SET_PID frame, "
        f"{f.full_cycles_per_setpoint_frame:.0f} cycles/setpoint frame\n"
        f"    longest poll() in the SET_PID flood: {f.longest_poll_span_cycles} cycles entry to return "
        f"({f.longest_poll_span_cycles / CPU_HZ * 1e6:.0f} us; budget {POLL_SPAN_BUDGET_CYCLES}, 5% of the control "
        f"period), {f.longest_set_pid_poll_cycles} of them decoding and dispatching\n"
        f"    back to back: {f.rx_bytes:,} bytes received, {f.rx_overruns} overruns, RX ISR latency "
        f"{f.worst_rx_isr_latency_cycles} cycles (one byte: {CYCLES_PER_BYTE}), longest loop pass "
        f"{f.worst_loop_pass_cycles} cycles; {f.realtime_ratio:.1f}x real time\n"
        f"    {line_use.report(f.line)}"
    )


def breakdown(f: Figures, top: int = 8) -> str:
    """Where the cycles of a SET_PID frame inside poll() go (per frame; handling marked)."""
    lines = [f"{f.example}: cycles per SET_PID frame inside poll() (decode+dispatch, and handling marked so)"]
    for key in ("file", "function", "line"):
        items = list(f.set_pid_breakdown.get(key, {}).items())
        shown = items[:top]
        rest = sum(v for _, v in items[top:])
        lines.append(f"  by {key}:")
        lines += [f"    {v:8.0f}  {k}" for k, v in shown]
        if items[top:]:
            lines.append(f"    {rest:8.0f}  ({len(items) - top} more)")
    return "\n".join(lines)


def all_figures() -> list[Figures]:
    return [measure(p.example, name) for name, p in sorted(PROFILES.items())]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = parser.parse_args(argv)
    figures = all_figures()
    if args.json:
        print(json.dumps([asdict(f) for f in figures], indent=2))
    else:
        for f in figures:
            print(report(f))
        for f in figures:
            print(breakdown(f))
    bad = [p for f in figures for p in problems(f)]
    for p in bad:
        print(f"OVER BUDGET: {p}", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
