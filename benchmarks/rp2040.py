"""The Pico firmware's budgets, measured on its flash image in rp2040js (cycle counts) and with
arm-none-eabi-size: the RP2040 column of docs/budgets.md.

    python3 benchmarks/rp2040.py            # the TB6612 robot on the Pico pinout, 115200 and 1 Mbaud
    python3 benchmarks/rp2040.py --json

Method. The harness (tools/rp2040/harness.mjs) counts the cycles the core executes (asleep in WFI
counts nothing) and, with --histogram, the cycles executed at every PC; arm-none-eabi-addr2line
maps each PC to its source file (the image is built with -g). For each baud rate, after the
handshake:

* idle: one second with no host bytes (control ticks and FEEDBACK at 50 Hz go on);
* flood: one second of SET_PID frames (27 bytes on the wire) sent back to back, each answered with
  an ACK (a frame not answered makes the run invalid).

Whole-frame cost per byte = (flood's cycles - idle's) / bytes received: the UART interrupt filling
the ring, the core reading it, COBS, CRC, length and id checks, unpacking and range checks, the
session rules, SET_PID applied and the ACK packed and written. Frame-decoder cycles per byte =
the flood's cycles less the idle's in the decoder's sources (frame_decoder.cpp/.h, crc16.cpp/.h,
cobs.cpp/.h and the generated roverlink_protocol.cpp's message bounds), per byte: what the
AVR's decoder figure counts. Flash and static RAM from the ELF's sections.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from collections import Counter
from dataclasses import asdict, dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.line_use import line_use
from emulator.backends.rp2040 import Rp2040Robot, pico_profile, pico_robot
from host_sdk import messages
from host_sdk.framing import FrameDecoder, encode_frame
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH
from roverlink.firmware.pico import build_pico

ROBOT = "diffdrive-tb6612"
BAUDS = (115_200, 1_000_000)
DECODER_SOURCES = ("frame_decoder.", "crc16.", "cobs.", "roverlink_protocol.cpp")
SECOND_US = 1_000_000
DECODER_BUDGET = 86
"""Cycles per byte of frame for the decoder: the AVR's bound (docs/budgets.md)."""
WHOLE_FRAME_BUDGET = 500
"""Cycles per byte of frame, everything a SET_PID costs (interrupt to ACK): 4 us per byte at
125 MHz, 40 % of the core at 1 Mbaud's byte every 10 us."""


@dataclass(frozen=True)
class Run:
    baud: int
    frames: int
    bytes: int
    whole_frame_cycles_per_byte: float
    decoder_cycles_per_byte: float
    idle_cycles_per_s: int
    line_share_100hz_feedback: float


def _sources(elf: Path, pcs: list[int]) -> dict[int, str]:
    """Source file name of each PC (addr2line; '?' where the ELF has no line)."""
    out = subprocess.run(
        ["arm-none-eabi-addr2line", "-e", str(elf), *(f"{pc:x}" for pc in pcs)],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.splitlines()
    return {pc: Path(line.split(":")[0]).name for pc, line in zip(pcs, out, strict=True)}


def _decoder_cycles(elf: Path, histogram: dict[int, int]) -> int:
    files = _sources(elf, sorted(histogram))
    return sum(c for pc, c in histogram.items() if files[pc].startswith(DECODER_SOURCES))


def measure(baud: int, image: Path, elf: Path) -> Run:
    decoder = FrameDecoder()
    with Rp2040Robot(pico_profile(ROBOT), image, baud=baud, histogram=True) as robot:
        robot.advance_us(20_000)
        robot.host_write(encode_frame(messages.Hello(PROTOCOL_VERSION, SPEC_HASH, 0, 0, 0), seq=0))
        robot.advance_us(20_000)
        decoder.feed(robot.host_read())
        c0, h0 = robot.harness.cycles(), robot.harness.histogram()
        robot.advance_us(SECOND_US)
        decoder.feed(robot.host_read())
        c1, h1 = robot.harness.cycles(), robot.harness.histogram()
        pid = messages.SetPid(wheel=0, kp=1.0, ki=6.0, kd=0.0, kf=1.25, ks=70.0)
        frame_len = len(encode_frame(pid, seq=1))
        byte_us = 10 * SECOND_US / baud
        frames, sent, acks = 0, 0, 0
        start = robot.now_us
        seq = 1
        while robot.now_us - start < SECOND_US:
            # Keep the host's side full: a frame's worth of bytes queued ahead of the line.
            while sent * byte_us < (robot.now_us - start) + frame_len * byte_us:
                robot.host_write(encode_frame(pid, seq=seq))
                seq = (seq + 1) & 0xFF
                frames += 1
                sent += frame_len
            robot.advance_us(1000)
            acks += sum(1 for f in decoder.feed(robot.host_read()) if isinstance(f.message, messages.Ack))
        robot.advance_us(200_000)  # the last frames answered
        acks += sum(1 for f in decoder.feed(robot.host_read()) if isinstance(f.message, messages.Ack))
        c2, h2 = robot.harness.cycles(), robot.harness.histogram()
    if acks != frames:
        raise SystemExit(f"{baud} baud: {frames} SET_PID frames, {acks} ACKs: the run is invalid")
    idle = c1 - c0
    flood_us = robot.now_us - start
    flood = (c2 - c1) - idle * flood_us / SECOND_US
    idle_hist = Counter(h1)
    idle_hist.subtract(h0)
    flood_hist = Counter(h2)
    flood_hist.subtract(h1)
    dec_idle = _decoder_cycles(elf, {pc: c for pc, c in idle_hist.items() if c > 0})
    dec_flood = _decoder_cycles(elf, {pc: c for pc, c in flood_hist.items() if c > 0})
    decoder_cycles = dec_flood - dec_idle * flood_us / SECOND_US
    return Run(
        baud=baud,
        frames=frames,
        bytes=sent,
        whole_frame_cycles_per_byte=round(flood / sent, 1),
        decoder_cycles_per_byte=round(decoder_cycles / sent, 1),
        idle_cycles_per_s=idle,
        line_share_100hz_feedback=round(line_use(messages.SetWheelSpeeds, baud).mcu_to_host, 4),
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", action="store_true", help="machine-readable output")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        runs = []
        sizes = None
        for baud in BAUDS:
            built = build_pico(pico_robot(ROBOT), Path(tmp) / str(baud), name=ROBOT, baud=baud)
            sizes = {"flash_bytes": built.flash_used, "sram_bytes": built.sram_used}
            runs.append(measure(baud, built.bin, built.elf))
    if args.json:
        print(json.dumps({"robot": ROBOT, **(sizes or {}), "runs": [asdict(r) for r in runs]}, indent=2))
        return 0
    assert sizes is not None
    print(f"{ROBOT} on a Pico: flash {sizes['flash_bytes']:,} B, static RAM {sizes['sram_bytes']:,} B")
    for r in runs:
        print(
            f"  {r.baud} baud: {r.frames} SET_PID frames ({r.bytes} B) in 1 s, all answered; "
            f"whole frame {r.whole_frame_cycles_per_byte} cycles/byte, decoder {r.decoder_cycles_per_byte} "
            f"cycles/byte; idle {r.idle_cycles_per_s:,} cycles/s of 125,000,000; "
            f"100 Hz FEEDBACK takes {r.line_share_100hz_feedback:.1%} of the MCU-to-host line"
        )
    print(f"  budgets: decoder <= {DECODER_BUDGET}, whole frame <= {WHOLE_FRAME_BUDGET} cycles/byte")
    return 0


if __name__ == "__main__":
    sys.exit(main())
