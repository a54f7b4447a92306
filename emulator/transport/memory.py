"""An in-memory serial port on the emulator's virtual clock, with pyserial's reading API.

Host code written against `serial.Serial` can use it unchanged: `read(n)` waits for bytes the way
pyserial does, except that the wait advances *virtual* time, so a test runs as fast as the CPU
allows and gives the same bytes every run. Opening the port resets the board (DTR), and so does
raising `dtr` again after dropping it, as on an Arduino with auto-reset.
"""

from __future__ import annotations

from collections.abc import Callable

from emulator.device import Emulator
from emulator.errors import EmulatorError

_STEP_US = 500
MAX_BLOCK_S = 3600.0
"""With timeout=None a read waits at most this long in virtual time (instead of forever)."""


class PortClosedError(EmulatorError, OSError):
    """Read or write on a MemorySerial that is not open."""


class MemorySerial:
    def __init__(
        self,
        emulator: Emulator,
        timeout: float | None = 0.1,
        *,
        dtr_reset_on_open: bool = True,
        do_not_open: bool = False,
    ) -> None:
        self.emulator = emulator
        self.timeout = timeout
        self.dtr_reset_on_open = dtr_reset_on_open
        self.port = f"emulator://{emulator.profile.name}?seed={emulator.seed}"
        self.is_open = False
        self._dtr = True
        self._buffer = bytearray()
        if not do_not_open:
            self.open()

    @property
    def baudrate(self) -> int:
        return self.emulator.h2m.baud

    def open(self) -> None:
        if self.is_open:
            return
        self.emulator.host_read()  # whatever the board sent while nobody listened is gone
        self._buffer.clear()
        self.is_open = True
        if self.dtr_reset_on_open:
            self.emulator.dtr_reset()

    def close(self) -> None:
        self.is_open = False
        self._buffer.clear()

    def __enter__(self) -> MemorySerial:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def dtr(self) -> bool:
        return self._dtr

    @dtr.setter
    def dtr(self, value: bool) -> None:
        if value and not self._dtr and self.is_open:
            self.emulator.dtr_reset()  # the auto-reset capacitor passes the DTR edge to RESET
        self._dtr = bool(value)

    def _pull(self) -> None:
        self._check_open()
        self._buffer += self.emulator.host_read()

    def _check_open(self) -> None:
        if not self.is_open:
            raise PortClosedError(f"{self.port} is not open")

    @property
    def in_waiting(self) -> int:
        self._pull()
        return len(self._buffer)

    def write(self, data: bytes) -> int:
        self._check_open()
        self.emulator.host_write(bytes(data))
        return len(data)

    def flush(self) -> None:
        """Bytes are on the (virtual) line as soon as they are written."""

    def read(self, size: int = 1) -> bytes:
        """Up to `size` bytes: returns when `size` are there or `timeout` (virtual) seconds passed."""
        self._wait(lambda: len(self._buffer) >= size)
        return self._take(size)

    def read_until(self, expected: bytes = b"\n", size: int | None = None) -> bytes:
        """Bytes up to and including `expected` (or `size` bytes, or what came before the timeout)."""

        def cut() -> int | None:
            index = self._buffer.find(expected)
            if index >= 0:
                end = index + len(expected)
                return end if size is None else min(end, size)
            return size if size is not None and len(self._buffer) >= size else None

        self._wait(lambda: cut() is not None)
        n = cut()
        return self._take(len(self._buffer) if n is None else n)

    def read_all(self) -> bytes:
        self._pull()
        return self._take(len(self._buffer))

    def _take(self, n: int) -> bytes:
        data = bytes(self._buffer[:n])
        del self._buffer[:n]
        return data

    def _wait(self, done: Callable[[], bool]) -> None:
        emu = self.emulator
        self._pull()
        timeout = MAX_BLOCK_S if self.timeout is None else self.timeout
        deadline = emu.now_us + round(timeout * 1e6)
        while not done() and emu.now_us < deadline:
            emu.advance_to_us(min(deadline, emu.now_us + _STEP_US))
            self._pull()

    def reset_input_buffer(self) -> None:
        self._pull()
        self._buffer.clear()

    def reset_output_buffer(self) -> None:
        """Written bytes are already on the line."""

    def advance(self, seconds: float) -> None:
        """Let virtual time pass without reading."""
        self.emulator.advance(seconds)
