"""The MCU: one fil_harness process (tools/simavr/fil_harness.c) running an example's ELF in simavr.

Each step is a synchronous request/reply over pipes: the harness runs the MCU for a number of
microseconds with the encoder positions it is given (turning each count change into quadrature
edges on the encoder pins) and the host's bytes, and reports the watched timer compare and port
registers and the bytes UART0 sent. Time is simavr's cycle counter (16 per us).
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

from emulator.backends.pipe import PipeProcess
from emulator.backends.simavr.wiring import BoardWiring
from emulator.errors import BackendError

ROOT = Path(__file__).resolve().parents[3]
HARNESS_DIR = ROOT / "tools" / "simavr"
BUILD_DIR = Path(os.environ.get("ROVERLINK_SIMAVR_BUILD", ROOT / "build" / "simavr"))
HARNESS = BUILD_DIR / "fil_harness"
HANDLER_FLAG = 0x1000000  # profile keys of PCs run inside a handler boundary (Harness.profile_handler)


class SimavrError(BackendError):
    """The harness or the firmware could not be built, started, or stopped unexpectedly."""


def build_harness() -> Path:
    """`make -C tools/simavr` (a no-op when up to date)."""
    result = subprocess.run(
        ["make", "-s", "-C", str(HARNESS_DIR), f"BUILD={BUILD_DIR}"], capture_output=True, text=True, check=False
    )
    if result.returncode != 0:
        raise SimavrError(f"building the simavr harness failed:\n{result.stdout}\n{result.stderr}")
    return HARNESS


def prebuilt_elf(example: str) -> Path:
    """The example's ELF from the folder ROVERLINK_SIMAVR_ELF_DIR names (<dir>/<example>/<example>.elf),
    for a SimavrRobot made without `elf=`. Building is the tools' job (`roverlink firmware build`,
    roverlink.firmware.build_example): the emulator runs a firmware, it does not compile one."""
    prebuilt = os.environ.get("ROVERLINK_SIMAVR_ELF_DIR")
    if not prebuilt:
        raise SimavrError(
            f"no ELF for {example}: pass elf= (e.g. roverlink.firmware.build_example({example!r}).elf) "
            "or set ROVERLINK_SIMAVR_ELF_DIR to a folder holding <example>/<example>.elf"
        )
    elf = Path(prebuilt) / example / f"{example}.elf"
    if not elf.is_file():
        raise SimavrError(f"ROVERLINK_SIMAVR_ELF_DIR={prebuilt}: no {elf}")
    return elf


class Harness:
    """One fil_harness process: the MCU. Steps are synchronous request/reply over pipes."""

    def __init__(
        self,
        wiring: BoardWiring,
        elf: Path,
        harness: Path | None = None,
        *,
        adc0_mv: int | None = None,
        line_ppb: int = 0,
    ) -> None:
        exe = harness if harness is not None else build_harness()
        self.wiring = wiring
        self.watch = wiring.watch()
        cmd = [str(exe), wiring.mcu, str(elf)]
        for a, b in wiring.encoders:
            cmd += ["--enc", a, b]
        for addr in self.watch:
            cmd += ["--watch", hex(addr)]
        if wiring.pcint_k:
            cmd.append("--pcint-k")
        if adc0_mv is not None:
            cmd += ["--adc0", str(adc0_mv)]
        if line_ppb:
            cmd += ["--line-ppb", str(line_ppb)]  # the host's bytes, in the drifting MCU's cycles
        self._proc = PipeProcess(cmd, ROOT, SimavrError, "simavr harness")
        self.cycle = 0

    @property
    def pid(self) -> int:
        """The harness process's id."""
        return self._proc.pid

    def _ask(self, command: str) -> list[str]:
        return self._proc.ask(command)

    def step(self, us: int, counts: list[int], rx: bytes) -> tuple[dict[int, int], bytes]:
        """Runs `us` of MCU time; returns the watched registers and the bytes UART0 sent."""
        n = len(self.wiring.encoders)
        reply = self._ask(f"S {us} {' '.join(str(c) for c in counts[:n])} {rx.hex() or '-'}")
        self.cycle = int(reply[1])
        raw = bytes.fromhex(reply[2]) if reply[2] != "-" else b""
        regs = dict(zip(self.watch, raw, strict=True))
        return regs, bytes.fromhex(reply[3]) if reply[3] != "-" else b""

    def reset(self) -> None:
        self._ask("R")

    def rx_stats(self) -> tuple[int, int, int]:
        """(longest UDR0-to-read latency in cycles, bytes read, overruns) since the last call."""
        r = self._ask("C")
        return int(r[1]), int(r[2]), int(r[3])

    def set_loop_marker(self, byte_address: int) -> None:
        """Counts main-loop passes from now on (see `loop_stats`)."""
        self._ask(f"L {byte_address}")

    def loop_stats(self) -> tuple[int, int, int, int]:
        """(passes, cycles, shortest pass, longest pass) since the last call."""
        r = self._ask("M")
        return int(r[1]), int(r[2]), int(r[3]), int(r[4])

    def profile_function(self, byte_address: int) -> None:
        """Profiles the calls of the function at that address from now on, interrupt handlers
        excluded (see `profile`); 0 stops."""
        self._ask(f"P {byte_address}")

    def profile_handler(self, byte_address: int) -> None:
        """Inside profiled calls, the cycles of calls of the function at that address are kept
        apart: `profile` reports them at PC + HANDLER_FLAG (0 clears every handler)."""
        self._ask(f"H {byte_address}")

    def profile(self) -> tuple[int, int, int, int, dict[int, int]]:
        """(calls, cycles, cheapest call, longest call less its handlers' cycles, cycles per PC byte
        address) since the last call."""
        r = self._ask("D")
        per_pc = {} if r[5] == "-" else {int(a, 16): int(c) for a, c in (t.split(":") for t in r[5:])}
        return int(r[1]), int(r[2]), int(r[3]), int(r[4]), per_pc

    def longest_call(self) -> int:
        """The longest profiled call since the last call of this, in cycles from its entry to its
        return (interrupts and handlers included: how long it held the main loop)."""
        return int(self._ask("W")[1])

    def close(self) -> None:
        self._proc.close()
