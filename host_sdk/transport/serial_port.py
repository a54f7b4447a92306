"""pyserial transport: device paths and every URL `serial.serial_for_url` understands."""

from __future__ import annotations

import contextlib
import os
import select
import stat
import threading
import time

import serial

from host_sdk.errors import TransportError
from host_sdk.transport.base import Transport
from host_sdk.transport.plugins import open_plugin, schemes

POLL_S = 0.01
"""pyserial's read timeout. Fixed, because changing it reconfigures a real port (a tcsetattr)."""
READ_SIZE = 4096
"""Most bytes taken per read (a full second at 115200 baud is 11,520)."""


class SerialTransport(Transport):
    """A serial port, pty, TCP socket (`socket://`), `loop://` or `spy://` port via pyserial: the
    board's, or a sensor's (which also drives DTR and switches baud)."""

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
        # A real device or pty has a file descriptor: read it directly (socket:// and loop:// have none).
        fd = getattr(self._port, "fd", None)
        self._fd: int | None = fd if isinstance(fd, int) and fd >= 0 else None
        self._poll = select.poll()
        if self._fd is not None:
            self._poll.register(self._fd, select.POLLIN)

    def read(self, timeout_s: float) -> bytes:
        fd = self._fd
        if fd is not None:
            return self._read_fd(fd, timeout_s)
        deadline = time.monotonic() + max(0.0, timeout_s)
        port = self._port
        try:
            while True:
                waiting = port.in_waiting
                data: bytes = port.read(waiting if waiting > 0 else 1)
                if data:
                    waiting = port.in_waiting  # the rest of what arrived with the first byte
                    return data + port.read(waiting) if waiting else data
                if time.monotonic() >= deadline:
                    return data
        except (serial.SerialException, OSError, TypeError, AttributeError) as exc:
            # TypeError/AttributeError: pyserial's own failure modes when the fd vanishes under it.
            if self._closed:
                return b""
            raise TransportError(f"reading {self.url} failed: {exc}", self.url, exc) from exc

    def _read_fd(self, fd: int, timeout_s: float) -> bytes:
        """A serial device or pty: one poll() and one read() of everything that is there. This is
        the receive path's only system-call pair per wake-up (pyserial's read() loops in Python)."""
        try:
            if not self._poll.poll(max(0.0, timeout_s) * 1000):
                return b""
            data = os.read(fd, READ_SIZE)
        except BlockingIOError:
            return b""
        except (OSError, ValueError) as exc:
            if self._closed:
                return b""
            raise TransportError(f"reading {self.url} failed: {exc}", self.url, exc) from exc
        if not data and not self._closed:
            error = OSError("the device reports data but gives none: unplugged, or opened by another program?")
            raise TransportError(f"reading {self.url} failed: {error}", self.url, error)
        return data

    def write(self, data: bytes) -> None:
        if not data:
            return
        try:
            with self._write_lock:
                self._port.write(data)
        except (serial.SerialException, OSError, TypeError, AttributeError) as exc:
            raise TransportError(f"writing {self.url} failed: {exc}", self.url, exc) from exc

    def set_dtr(self, level: bool) -> None:
        # A pty or socket has no modem lines; pyserial says so with an error, which is no failure here.
        with contextlib.suppress(serial.SerialException, OSError):
            self._port.dtr = level

    def set_baud(self, baud: int) -> None:
        try:
            self._port.baudrate = baud
        except (serial.SerialException, OSError) as exc:
            raise TransportError(f"setting {self.url} to {baud} baud failed: {exc}", self.url, exc) from exc
        self.baud = baud

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
            "from a checkout, use the checkout's .venv, which `bash scripts/demo.sh` makes: .venv/bin/python)",
            url,
        )
    return SerialTransport(url, baud)
