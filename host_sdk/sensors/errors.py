"""Sensor driver errors, in RoverLink's one exception tree."""

from __future__ import annotations

from host_sdk.errors import RoverLinkError


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
    """A sensor could not be opened; names the kind of device, where, and why."""
