"""pyserial transport: device paths and every URL `serial.serial_for_url` understands."""

from __future__ import annotations

import contextlib
import os
import stat
import threading
import time

import serial

from host_sdk.errors import TransportError
from host_sdk.transport.base import Transport
from host_sdk.transport.plugins import open_plugin, schemes

POLL_S = 0.01
"""pyserial's read timeout. Fixed, because changing it reconfigures a real port (a tcsetattr)."""


class SerialTransport(Transport):
    """A serial port, pty, TCP socket (`socket://`), `loop://` or `spy://` port via pyserial."""

    def __init__(self, url: str, baud: int = 115200) -> None:
        self.url = url
        self.baud = baud
        self._write_lock = threading.Lock()
        kwargs: dict[str, object] = {"baudrate": baud, "timeout": POLL_S, "write_timeout": 2.0}
        if "://" not in url:
            kwargs["exclusive"] = True  # two programs on one port corrupt each other's frames
        try:
            self._port = serial.serial_for_url(url, **kwargs)
        except (serial.SerialException, OSError, ValueError) as exc:
            why = _not_a_port(url) or str(exc)
            raise TransportError(
                f"could not open {url} at {baud} baud: {why} (`roverlink ports` lists the serial ports)", url, exc
            ) from exc
        self._closed = False

    def read(self, timeout_s: float) -> bytes:
        deadline = time.monotonic() + max(0.0, timeout_s)
        port = self._port
        try:
            while True:
                waiting = port.in_waiting
                data: bytes = port.read(waiting if waiting > 0 else 1)
                if data or time.monotonic() >= deadline:
                    return data
        except (serial.SerialException, OSError, TypeError, AttributeError) as exc:
            # TypeError/AttributeError: pyserial's own failure modes when the fd vanishes under it.
            if self._closed:
                return b""
            raise TransportError(f"reading {self.url} failed: {exc}", self.url, exc) from exc

    def write(self, data: bytes) -> None:
        if not data:
            return
        try:
            with self._write_lock:
                self._port.write(data)
        except (serial.SerialException, OSError, TypeError, AttributeError) as exc:
            raise TransportError(f"writing {self.url} failed: {exc}", self.url, exc) from exc

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        with contextlib.suppress(serial.SerialException, OSError):
            self._port.close()


def _not_a_port(url: str) -> str | None:
    """Why a path cannot be a serial port, in words, or None (a URL, or a device that may be one)."""
    if "://" in url:
        return None
    try:
        mode = os.stat(url).st_mode
    except FileNotFoundError:
        return "there is no such device"
    except OSError:
        return None
    if stat.S_ISDIR(mode):
        return "it is a directory, not a serial port"
    if not stat.S_ISCHR(mode):
        return "it is a file, not a serial port"
    try:
        fd = os.open(url, os.O_RDONLY | os.O_NONBLOCK | os.O_NOCTTY)
    except OSError:
        return None
    try:
        return None if os.isatty(fd) else "it is a device, but not a serial port"
    finally:
        os.close(fd)


def open_transport(url: str, baud: int = 115200) -> Transport:
    """The transport for `url`: a scheme a plugin registered (`emu://` when the emulator is
    installed) goes to that plugin, anything else to pyserial."""
    transport = open_plugin(url, baud)
    if transport is not None:
        return transport
    if url.startswith("emu:") and "emu" not in schemes():
        raise TransportError(
            f"{url}: no transport is registered for emu:// (the emulator package is not installed; "
            "from a checkout: python3 -m pip install -e .)",
            url,
        )
    return SerialTransport(url, baud)
