"""Sensor driver errors, in RoverLink's one exception tree."""

from __future__ import annotations

from host_sdk.errors import RoverLinkError
from host_sdk.extras import MissingDependencyError


class SensorTimeoutError(RoverLinkError, TimeoutError):
    """A sensor did not answer or deliver in time; says what was waited for and what was heard."""

    def __init__(self, url: str, what: str, timeout_s: float, heard: str) -> None:
        self.url = url
        self.what = what
        self.timeout_s = timeout_s
        super().__init__(f"{url}: no {what} within {timeout_s:g} s ({heard})")


class SensorClosedError(RoverLinkError, ConnectionError):
    """A call on a sensor driver that was closed."""


class SensorOpenError(RoverLinkError, OSError):
    """A sensor could not be opened; names the kind of device, where, and why. `kind` is lidar,
    imu or camera when known ("" otherwise)."""

    def __init__(self, message: str, kind: str = "") -> None:
        self.kind = kind
        super().__init__(message)


class CameraBackendError(MissingDependencyError):
    """A camera route's software is missing (a module, or a feature the OpenCV build lacks): names
    the source, the missing piece, and what to install. An ImportError, as MissingDependencyError
    is, so a tool reports it in one line."""

    def __init__(self, source: str, missing: str, install: str) -> None:
        self.source = source
        self.module = missing
        self.install = install
        self.extra = ""
        super(MissingDependencyError, self).__init__(f"camera {source}: {missing}; {install}")
