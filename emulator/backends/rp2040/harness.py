"""One rp2040js process (tools/rp2040/harness.mjs) running an RP2040 image: an SRAM image, or
(`flash=True`) the flash image a Pico runs, boot block first.

Each step is a synchronous request/reply over pipes, as with the simavr harness: the harness runs
the chip for a number of microseconds with the encoder positions it is given (each count change a
quadrature edge on the encoder's two pins) and the host's bytes for UART0, and reports each
watched pin's share of the step spent high, its level at the end and the pulse its PWM slice is
set to, and the bytes UART0 put on the line, paced at the baud rate.
Time is the simulation clock's, in nanoseconds (the core at 125 MHz, asleep through WFI); the ring
oscillator's noise, which rp2040js does not model, comes from a generator seeded with `seed`.
"""

from __future__ import annotations

import os
import shutil
from dataclasses import dataclass
from pathlib import Path

from emulator.backends.pipe import PipeProcess
from emulator.errors import BackendError

ROOT = Path(__file__).resolve().parents[3]
HARNESS_DIR = ROOT / "tools" / "rp2040"
SCRIPT = HARNESS_DIR / "harness.mjs"
BUILD_DIR = Path(os.environ.get("ROVERLINK_RP2040_BUILD", ROOT / "build" / "rp2040"))


class Rp2040Error(BackendError):
    """The harness could not start (no Node.js, rp2040js not installed), or stopped unexpectedly."""


@dataclass(frozen=True, slots=True)
class PinReading:
    high: float
    """Part of the step the pin was high, 0..1 (a PWM output's duty over whole periods)."""
    level: bool
    """Its level at the end of the step."""
    pulse_us: float = 0.0
    """The high time per period its PWM slice is set to (0: not on a running slice): the width
    the firmware set, read from the slice's compare register as simavr reads a timer's."""


def node_modules() -> Path:
    """tools/rp2040/node_modules, as `npm ci` installs it from the lockfile."""
    modules = HARNESS_DIR / "node_modules" / "rp2040js"
    if not modules.is_dir():
        raise Rp2040Error(f"rp2040js is not installed: run `npm ci --prefix {HARNESS_DIR.relative_to(ROOT)}`")
    return modules


class Harness:
    """One harness process: the chip. Steps are synchronous request/reply over pipes."""

    def __init__(
        self,
        image: Path,
        *,
        encoders: tuple[tuple[int, int], ...] = (),
        watch: tuple[int, ...] = (),
        baud: int = 115200,
        seed: int = 1,
        flash: bool = False,
        histogram: bool = False,
    ) -> None:
        node = shutil.which("node")
        if node is None:
            raise Rp2040Error("Node.js (`node`) is not on PATH: the rp2040 backend runs rp2040js in it")
        node_modules()
        image = Path(image).resolve()  # the harness runs in tools/rp2040: a relative path would miss
        if not image.is_file():
            raise Rp2040Error(f"no RP2040 image {image} (roverlink firmware build --robot FILE writes one)")
        self.encoders = encoders
        self.watch = watch
        cmd = [node, str(SCRIPT), str(image), "--baud", str(baud), "--seed", str(seed)]
        if flash:  # a flash image: its boot block runs first, as on a Pico
            cmd.append("--flash")
        for a, b in encoders:
            cmd += ["--enc", str(a), str(b)]
        for pin in watch:
            cmd += ["--watch", str(pin)]
        if histogram:
            cmd.append("--histogram")
        self._proc = PipeProcess(cmd, HARNESS_DIR, Rp2040Error, "rp2040 harness")
        self.nanos = 0

    def _ask(self, command: str) -> list[str]:
        return self._proc.ask(command)

    def step(self, us: int, counts: list[int], rx: bytes) -> tuple[dict[int, PinReading], bytes]:
        """Runs `us` of the chip's time; returns the watched pins and the bytes UART0 sent."""
        n = len(self.encoders)
        reply = self._ask(f"S {us} {' '.join(str(c) for c in counts[:n])} {rx.hex() or '-'}")
        self.nanos = int(reply[1])
        pins: dict[int, PinReading] = {}
        if reply[2] != "-":
            for pin, reading in zip(self.watch, reply[2].split(","), strict=True):
                high, level, pulse_ns = reading.split(":")
                pins[pin] = PinReading(int(high) / 1e6, level == "1", int(pulse_ns) / 1000)
        return pins, bytes.fromhex(reply[3]) if reply[3] != "-" else b""

    def reset(self) -> None:
        """The board's reset: the chip starts the image again."""
        self._ask("R")

    def cycles(self) -> int:
        """Cycles the core executed (not asleep) since the start."""
        return int(self._ask("C")[1])

    def histogram(self) -> dict[int, int]:
        """Cycles executed at each PC since the start (`histogram=True`; empty without)."""
        reply = self._ask("P")
        if reply[1] == "-":
            return {}
        return {int(pc, 16): int(c) for pc, c in (item.split(":") for item in reply[1].split(","))}

    def hang(self) -> None:
        """The core stops executing (a firmware stuck with its interrupts off); the peripherals and
        the watchdog go on, and the next reset ends it."""
        self._ask("H")

    @property
    def resets(self) -> int:
        """Resets so far, a watchdog's among them."""
        return int(self._ask("N")[1])

    def close(self) -> None:
        self._proc.close()

    def __enter__(self) -> Harness:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
