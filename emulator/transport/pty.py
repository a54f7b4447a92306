"""A pseudo-terminal that any serial program (pyserial, a terminal) can open like a real port.

The emulator holds the master side. "Port opened" (which resets the board, as DTR does on an
Arduino) is detected two ways:

* inotify on the slave's device node (/dev/pts/N): the kernel reports every open and close, so
  even a close immediately followed by a reopen is seen as a new open;
* where inotify is not available, the master's poll state: Linux reports POLLHUP on the master
  while no process has the slave open. A reopen faster than the serving loop's pass (1 ms) is
  then missed.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import errno
import os
import select
import struct
import termios
import tty

_IN_OPEN = 0x20
_IN_CLOSE_WRITE = 0x08
_IN_CLOSE_NOWRITE = 0x10
_EVENT = struct.Struct("iIII")


class _Inotify:
    """Open/close events of one file, through libc's inotify (Linux)."""

    def __init__(self, path: str) -> None:
        name = ctypes.util.find_library("c")
        libc = ctypes.CDLL(name, use_errno=True)
        fd = libc.inotify_init1(os.O_NONBLOCK | os.O_CLOEXEC)
        if fd < 0:
            raise OSError(ctypes.get_errno(), "inotify_init1 failed")
        mask = _IN_OPEN | _IN_CLOSE_WRITE | _IN_CLOSE_NOWRITE
        if libc.inotify_add_watch(fd, path.encode(), mask) < 0:
            os.close(fd)
            raise OSError(ctypes.get_errno(), f"inotify_add_watch({path}) failed")
        self.fd: int = fd

    def events(self) -> list[int]:
        """+1 for each open, -1 for each close since the last call, in the order they happened."""
        out: list[int] = []
        while True:
            try:
                data = os.read(self.fd, 4096)
            except BlockingIOError:
                return out
            offset = 0
            while offset + _EVENT.size <= len(data):
                _, mask, _, length = _EVENT.unpack_from(data, offset)
                offset += _EVENT.size + length
                if mask & _IN_OPEN:
                    out.append(1)
                if mask & (_IN_CLOSE_WRITE | _IN_CLOSE_NOWRITE):
                    out.append(-1)

    def close(self) -> None:
        os.close(self.fd)


class PtyEndpoint:
    def __init__(self) -> None:
        self.master, slave = os.openpty()
        self.name = os.ttyname(slave)
        # Raw from the start (no echo, no CR/LF translation) for programs that do not set it.
        tty.setraw(slave)
        os.close(slave)
        os.set_blocking(self.master, False)
        self._poll = select.poll()
        self._poll.register(self.master, select.POLLIN)
        self._pending = bytearray()
        self._openers = 0
        self._hup_connected = False
        self._inotify: _Inotify | None
        try:
            self._inotify = _Inotify(self.name)
        except (OSError, AttributeError, TypeError):
            self._inotify = None

    def _hup(self) -> bool:
        return any(ev & select.POLLHUP for _, ev in self._poll.poll(0))

    def poll(self) -> tuple[bool, int]:
        """(a host has the port open now, how many times it went from closed to open since the
        last poll). A second program opening a port that is already open does not count."""
        if self._inotify is not None:
            first_opens = 0
            for change in self._inotify.events():
                if change > 0 and self._openers == 0:
                    first_opens += 1  # DTR rises only when the port goes from closed to open
                self._openers = max(0, self._openers + change)
            return self._openers > 0, first_opens
        connected = not self._hup()
        edge = connected and not self._hup_connected
        self._hup_connected = connected
        return connected, int(edge)

    def on_connect(self) -> None:
        self._pending.clear()
        with contextlib.suppress(termios.error):
            termios.tcflush(self.master, termios.TCOFLUSH)

    def read(self) -> bytes:
        try:
            return os.read(self.master, 4096)
        except BlockingIOError:
            return b""
        except OSError as exc:
            if exc.errno == errno.EIO:  # no slave open right now
                return b""
            raise

    def write(self, data: bytes) -> None:
        self._pending += data
        try:
            n = os.write(self.master, self._pending)
        except BlockingIOError:
            n = 0
        except OSError as exc:
            if exc.errno != errno.EIO:
                raise
            n = len(self._pending)
        del self._pending[:n]
        if len(self._pending) > 65536:
            # Nobody reads: an adapter's buffer overflows too. Keep the newest bytes.
            del self._pending[: len(self._pending) - 65536]

    def wait(self, timeout_s: float) -> None:
        fds: list[int] = [] if self._hup() else [self.master]
        if self._inotify is not None:
            fds.append(self._inotify.fd)
        select.select(fds, [], [], timeout_s)  # (poll() would return at once on POLLHUP)

    def close(self) -> None:
        if self._inotify is not None:
            self._inotify.close()
        os.close(self.master)
