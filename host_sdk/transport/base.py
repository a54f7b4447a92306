"""The Transport interface: read with a timeout, write, close, and the clock to use with it.

The board and every serial sensor (lidar, IMU) are read through it: one way to open a URL, one
read loop, one mapping of errors to TransportError."""

from __future__ import annotations

import abc
import time
from collections.abc import Mapping
from types import MappingProxyType

NO_ENDPOINTS: Mapping[str, str] = MappingProxyType({})


class Transport(abc.ABC):
    """A byte pipe to a RoverLink board or a sensor. Implementations raise TransportError on failure."""

    url: str
    """What was opened, for messages."""
    virtual: bool = False
    """True when `read()` drives a virtual clock (no I/O thread is needed, or wanted)."""
    profile: str | None = None
    """The reference robot this transport is known to reach (an emulator's profile), else None:
    Robot.connect then takes the kinematics from the firmware's IDENTITY."""
    robot_file: str | None = None
    """The robot file (docs/robot-file.md) the device behind this transport was built from (an
    `emu://?robot=PATH` emulator), else None: Robot.connect takes its kinematics from it."""
    device: object | None = None
    """The in-process device behind the URL (an emulator: ground truth, fault injection), else None."""

    @property
    def endpoints(self) -> Mapping[str, str]:
        """URLs of the sensors attached to the device behind this transport, by kind (`lidar`, `imu`,
        `camera`, and `target`: an emu:// robot's, docs/sensors.md), for the SDK's sensor drivers
        (host_sdk.sensors). Empty for a board on a cable."""
        return NO_ENDPOINTS

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

    def set_dtr(self, level: bool) -> None:
        """Drive the DTR modem line (the RPLIDAR A1's adapter switches its motor with it). A transport
        without modem lines (a socket, an emulated device) ignores it."""
        return  # no modem lines here

    def set_baud(self, baud: int) -> None:
        """Switch the line's speed (after a device was told to change its own). A transport without a
        line speed ignores it."""
        return  # no line speed here

    def __enter__(self) -> Transport:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
