"""Emulator errors, rooted in RoverLink's single exception tree (`protocol.errors.RoverLinkError`).

Each leaf also inherits the built-in it behaves like, so `except ValueError` keeps working.
"""

from __future__ import annotations

from protocol.errors import RoverLinkError


class EmulatorError(RoverLinkError):
    """Root of the errors raised by the emulator."""


class UnknownProfileError(EmulatorError, ValueError):
    """A profile name that is not one of the reference robots."""

    def __init__(self, name: str, valid: list[str]) -> None:
        self.name = name
        self.valid = valid
        super().__init__(f"unknown emulator profile {name!r}: choose one of {', '.join(valid)}")


class FaultSpecError(EmulatorError, ValueError):
    """A --faults specification that does not parse; names the offending token."""

    def __init__(self, token: str, problem: str) -> None:
        self.token = token
        self.problem = problem
        super().__init__(f"bad fault spec token {token!r}: {problem}")


class EmulatorValueError(EmulatorError, ValueError):
    """An emulator argument outside its allowed range."""

    def __init__(self, name: str, value: object, allowed: str) -> None:
        self.name = name
        self.value = value
        self.allowed = allowed
        super().__init__(f"{name} = {value!r} is not allowed: {allowed}")


class BackendError(EmulatorError, RuntimeError):
    """A firmware backend (simavr, rp2040js) could not be built, started, or stopped unexpectedly,
    or cannot do what was asked."""
