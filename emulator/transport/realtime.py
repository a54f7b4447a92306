"""Serve the emulator in real time over an endpoint (a pseudo-terminal or a TCP socket).

The loop keeps virtual time equal to wall time (time.monotonic) times `speed`: each pass it
advances the emulator to now, hands it what the host wrote, and writes back what the MCU sent.
When a host connects (opens the pty, connects to the socket) the board gets a DTR reset, as an
Arduino does when its port is opened; while nobody is connected the MCU's output is discarded, as a
USB-serial adapter does.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from typing import Protocol, TextIO

from emulator.device import Emulator
from emulator.truth import FaultRecord


class Endpoint(Protocol):
    name: str

    def poll(self) -> tuple[bool, int]:
        """(is a host attached now, how many times one attached since the last poll)."""
        ...

    def on_connect(self) -> None:
        """A host just attached: drop anything stale."""
        ...

    def read(self) -> bytes: ...

    def write(self, data: bytes) -> None: ...

    def wait(self, timeout_s: float) -> None:
        """Block until the host writes or `timeout_s` passes."""
        ...

    def close(self) -> None: ...


def serve(
    emu: Emulator,
    endpoint: Endpoint,
    stop: Callable[[], bool],
    *,
    dtr_reset_on_open: bool = True,
    speed: float = 1.0,
    log: TextIO | None = sys.stderr,
) -> None:
    wall0 = time.monotonic()
    virt0 = emu.now_us
    connected = False
    reported_faults = len(emu.faults)
    reported_boots = 0  # the power-on boot too
    lag_warned = False
    while not stop():
        now_connected, opens = endpoint.poll()
        if opens:
            endpoint.on_connect()
            emu.host_read()  # sent while nobody listened: gone
            _say(log, f"host connected to {endpoint.name}")
            if dtr_reset_on_open:
                emu.dtr_reset()
        elif connected and not now_connected:
            _say(log, f"host disconnected from {endpoint.name}")
        connected = now_connected
        target = virt0 + int((time.monotonic() - wall0) * 1e6 * speed)
        if target > emu.now_us:
            emu.advance_to_us(target)
            behind = (time.monotonic() - wall0) * 1e6 * speed - (emu.now_us - virt0)
            if behind > 200_000 and not lag_warned:
                lag_warned = True
                _say(log, f"warning: the emulator is {behind / 1000:.0f} ms behind real time (CPU too slow?)")
        if connected:
            data = endpoint.read()
            if data:
                emu.host_write(data)
        out = emu.host_read()
        if connected and out:
            endpoint.write(out)
        if log is not None:
            report_faults(emu.faults[reported_faults:], lambda text: _say(log, text))
            reported_faults = len(emu.faults)
            for boot_id in emu.boot_ids[reported_boots:]:
                _say(log, f"t={emu.now_us / 1e6:.3f}s boot, boot_id 0x{boot_id:08X}")
            reported_boots = len(emu.boot_ids)
        endpoint.wait(0.001 if connected else 0.01)


def _say(log: TextIO | None, text: str) -> None:
    if log is not None:
        print(f"[emulator] {text}", file=log, flush=True)


def report_faults(records: Sequence[FaultRecord], say: Callable[[str], None]) -> None:
    """Progress lines for fault records (not every flipped, dropped or inserted byte)."""
    for record in records:
        if record.kind not in ("bitflip", "drop", "insert"):
            say(f"t={record.time_us / 1e6:.3f}s fault {record.kind} {record.detail}")
