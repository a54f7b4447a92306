"""Serve the emulator in real time over an endpoint (a pseudo-terminal or a TCP socket).

The loop keeps virtual time equal to wall time (time.monotonic) times `speed`: each pass it
advances the emulator to now, hands it what the host wrote, and writes back what the MCU sent.
When a host connects (opens the pty, connects to the socket) the board gets a DTR reset, as an
Arduino does when its port is opened; while nobody is connected the MCU's output is discarded, as a
USB-serial adapter does.
"""

from __future__ import annotations

import json
import math
import sys
import time
from collections.abc import Callable, Sequence
from typing import Protocol, TextIO

from emulator.sensors.serial import LidarDevice
from emulator.transport.serve_log import collision_line, fault_line, stamp
from emulator.truth import FaultRecord
from emulator.world.world import Collision


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


class SerialPeripheral(Protocol):
    """An emulated sensor on its own port (emulator.sensors): bytes in and out at virtual times."""

    def host_write(self, data: bytes, now_us: int) -> None: ...

    def host_read(self, now_us: int) -> bytes: ...


class ServedDevice(Protocol):
    """What the loop serves: the Python emulator or the firmware in simavr (its PlantLoop)."""

    @property
    def now_us(self) -> int: ...

    @property
    def faults(self) -> Sequence[FaultRecord]: ...

    @property
    def boot_ids(self) -> Sequence[int]: ...

    def advance_to_us(self, t_us: int) -> None: ...

    def host_read(self) -> bytes: ...

    def host_write(self, data: bytes) -> None: ...

    def dtr_reset(self) -> None: ...


def serve(
    device: ServedDevice,
    endpoint: Endpoint,
    stop: Callable[[], bool],
    *,
    dtr_reset_on_open: bool = True,
    speed: float = 1.0,
    log: TextIO | None = sys.stderr,
    tag: str = "emulator",
    extras: Sequence[tuple[Endpoint, SerialPeripheral]] = (),
    truth: TextIO | None = None,
) -> float:
    """Serve until `stop()`; returns how much faster than real time the device ran while busy
    (simulated seconds per wall second spent advancing it). Progress lines go to `log` as "[tag] ...".
    `extras` are the sensors' own ports, pumped in the same pass (their clock is the device's).
    `truth` gets ground truth as JSON lines on CLOCK_MONOTONIC: `{"lidar_rear_s": t}` when a
    lidar's rotor passes its rear (LidarDevice.on_rear)."""
    wall0 = time.monotonic()
    virt0 = device.now_us
    if truth is not None:
        _record_truth(truth, extras, lambda t_us: wall0 + (t_us - virt0) / 1e6 / speed)
    connected = False
    busy_s = 0.0
    reported_faults = 0  # the standing ones too (a drop rate from the start)
    reported_boots = 0  # the power-on boot too
    reported_collisions = 0
    # Only the Python emulator has a world (--world): the robot's collisions in it.
    collisions: Sequence[Collision] = getattr(getattr(device, "world", None), "collisions", ())
    lag_warned = False
    worst_behind_us = 0.0  # said at the end: a board model behind real time fails safe on time it never had

    def say(text: str) -> None:
        if log is not None:
            print(f"[{tag}] {text}", file=log, flush=True)

    while not stop():
        now_connected, opens = endpoint.poll()
        if opens:
            endpoint.on_connect()
            device.host_read()  # sent while nobody listened: gone
            say(f"host connected to {endpoint.name}")
            if dtr_reset_on_open:
                device.dtr_reset()
        elif connected and not now_connected:
            say(f"host disconnected from {endpoint.name}")
        connected = now_connected
        data = endpoint.read() if connected else b""
        # The bytes are the board's when they were read, not at the end of the last pass: given to
        # it before catching up to now, they reached it early, by up to a pass (the sensors' work,
        # the wait) or a whole stall, e.g. into the control tick before the one they came in.
        target = virt0 + int((time.monotonic() - wall0) * 1e6 * speed)
        if target > device.now_us:
            t0 = time.monotonic()
            device.advance_to_us(target)
            busy_s += time.monotonic() - t0
            behind = (time.monotonic() - wall0) * 1e6 * speed - (device.now_us - virt0)
            worst_behind_us = max(worst_behind_us, behind)
            if behind > 200_000 and not lag_warned:
                lag_warned = True
                say(f"warning: {behind / 1000:.0f} ms behind real time (CPU too slow?)")
        if data:
            device.host_write(data)
        out = device.host_read()
        if connected and out:
            endpoint.write(out)
        for port, peripheral in extras:
            _pump(port, peripheral, device.now_us, say)
        if log is not None:
            report_faults(device.faults[reported_faults:], say)
            reported_faults = len(device.faults)
            for hit in collisions[reported_collisions:]:
                say(collision_line(hit))
            reported_collisions = len(collisions)
            for boot_id in device.boot_ids[reported_boots:]:
                say(f"{stamp(device.now_us)} boot, boot_id 0x{boot_id:08X}")
            reported_boots = len(device.boot_ids)
        endpoint.wait(0.001 if connected else 0.01)
    say(f"longest lag behind real time: {worst_behind_us / 1000:.0f} ms")
    simulated_s = (device.now_us - virt0) / 1e6
    return simulated_s / busy_s if busy_s > 0 else math.inf


def _record_truth(
    truth: TextIO, extras: Sequence[tuple[Endpoint, SerialPeripheral]], wall_s: Callable[[int], float]
) -> None:
    """Each lidar's rear passes to `truth`, at `wall_s` of their virtual time (CLOCK_MONOTONIC)."""

    def rear(t_us: int) -> None:
        truth.write(json.dumps({"lidar_rear_s": round(wall_s(t_us), 6)}) + "\n")

    for _, peripheral in extras:
        if isinstance(peripheral, LidarDevice):
            peripheral.on_rear = rear


def _pump(port: Endpoint, peripheral: SerialPeripheral, now_us: int, say: Callable[[str], None]) -> None:
    attached, opens = port.poll()
    if opens:
        port.on_connect()
        say(f"host connected to {port.name}")
    if attached:
        data = port.read()
        if data:
            peripheral.host_write(data, now_us)
    out = peripheral.host_read(now_us)  # drained either way: an unread adapter loses its bytes
    if attached and out:
        port.write(out)


def report_faults(records: Sequence[FaultRecord], say: Callable[[str], None]) -> None:
    """Progress lines for fault records (not every flipped, dropped or inserted byte)."""
    for record in records:
        line = fault_line(record)
        if line is not None:
            say(line)
