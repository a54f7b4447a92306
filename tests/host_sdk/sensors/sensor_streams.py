"""Shared fixtures: byte streams recorded from the emulated devices (virtual clock, seed 5)."""

from __future__ import annotations

import functools

from emulator import Emulator
from emulator.sensors import attach


@functools.cache
def recorded(kind: str, model: str, seconds: float = 0.6) -> bytes:
    """What the device sent to a host that asked for info, health and a scan (or just listened)."""
    emu = Emulator("diffdrive-bts7960", seed=5)
    rig = attach(emu, "random:5", **({kind: model}))
    dev = rig.devices[kind]
    if model == "rplidar-a1":
        dev.host_write(b"\xa5\x50\xa5\x52\xa5\x59", emu.now_us)
        emu.advance(0.01)
        dev.host_write(b"\xa5\x20", emu.now_us)
    elif model == "ydlidar-f4":
        dev.host_write(b"\xa5\x90", emu.now_us)
        emu.advance(0.01)
        dev.host_write(b"\xa5\x92", emu.now_us)
        emu.advance(0.01)
        dev.host_write(b"\xa5\x60", emu.now_us)
    emu.advance(seconds)
    return bytes(dev.host_read(emu.now_us))
