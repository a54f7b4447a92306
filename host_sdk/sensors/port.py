"""The byte pipe a sensor driver owns: a serial port through pyserial, or a plugin's endpoint.

`SensorPort(url, baud)` opens `/dev/ttyUSB0`, any pyserial URL, or a URL whose scheme a package
registered in the `roverlink.transports` entry points (the emulator's `emudev://`, an in-process
device next to an `emu://` robot). Reads return whatever arrived; `clock()` is the time base the
driver stamps data with (the host's monotonic clock, or the emulator's virtual clock).
"""

from __future__ import annotations

import contextlib
import time
from typing import Any

import serial

from host_sdk.errors import TransportError
from host_sdk.transport.plugins import open_plugin


class SensorPort:
    def __init__(self, url: str, baud: int) -> None:
        self.url = url
        self.baud = baud
        self._plugin = open_plugin(url, baud)
        self._serial: Any = None
        if self._plugin is None:
            try:
                self._serial = serial.serial_for_url(url, baudrate=baud, timeout=0.01, exclusive="://" not in url)
            except (serial.SerialException, OSError, ValueError) as exc:
                raise TransportError(f"could not open {url} at {baud} baud: {exc}", url, exc) from exc

    @property
    def virtual(self) -> bool:
        """True when reads move an emulator's virtual clock (no I/O thread wanted)."""
        return bool(self._plugin is not None and self._plugin.virtual)

    def clock(self) -> float:
        return self._plugin.clock() if self._plugin is not None else time.monotonic()

    def read(self, timeout_s: float) -> bytes:
        """Bytes that arrived; waits up to `timeout_s` for the first."""
        if self._plugin is not None:
            return self._plugin.read(timeout_s)
        port = self._serial
        deadline = time.monotonic() + max(0.0, timeout_s)
        try:
            while True:
                waiting = port.in_waiting
                data: bytes = port.read(waiting if waiting > 0 else 1)
                if data or time.monotonic() >= deadline:
                    return data
        except (serial.SerialException, OSError) as exc:
            raise TransportError(f"reading {self.url} failed: {exc}", self.url, exc) from exc

    def write(self, data: bytes) -> None:
        if self._plugin is not None:
            self._plugin.write(data)
            return
        try:
            self._serial.write(data)
        except (serial.SerialException, OSError) as exc:
            raise TransportError(f"writing {self.url} failed: {exc}", self.url, exc) from exc

    def set_dtr(self, level: bool) -> None:
        """Drive the adapter's DTR line (the RPLIDAR A1's adapter switches its motor with it); a port
        without modem lines (a pty, a socket) ignores it."""
        if self._serial is not None:
            with contextlib.suppress(serial.SerialException, OSError):
                self._serial.dtr = level

    def set_baud(self, baud: int) -> None:
        self.baud = baud
        if self._serial is not None:
            self._serial.baudrate = baud

    def close(self) -> None:
        if self._plugin is not None:
            self._plugin.close()
        elif self._serial is not None:
            with contextlib.suppress(serial.SerialException, OSError):
                self._serial.close()
