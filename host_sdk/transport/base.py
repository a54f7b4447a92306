"""The Transport interface: read with a timeout, write, close, and the clock to use with it."""

from __future__ import annotations

import abc
import time


class Transport(abc.ABC):
    """A byte pipe to a RoverLink board. Implementations raise TransportError on failure."""

    url: str
    """What was opened, for messages."""
    virtual: bool = False
    """True when `read()` drives a virtual clock (no I/O thread is needed, or wanted)."""
    profile: str | None = None
    """The reference robot this transport is known to reach (an emulator's profile), else None:
    Robot.connect then takes the kinematics from the firmware's IDENTITY."""
    device: object | None = None
    """The in-process device behind the URL (an emulator: ground truth, fault injection), else None."""

    @abc.abstractmethod
    def read(self, timeout_s: float) -> bytes:
        """Bytes received so far; waits up to `timeout_s` for the first one. Empty on timeout."""

    @abc.abstractmethod
    def write(self, data: bytes) -> None:
        """Send `data` (whole)."""

    @abc.abstractmethod
    def close(self) -> None:
        """Release the port. Idempotent."""

    def clock(self) -> float:
        """Seconds on the clock this transport's timing is measured with."""
        return time.monotonic()

    def __enter__(self) -> Transport:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
