"""What the session reports (`Session.take_events()`)."""

from __future__ import annotations

from dataclasses import dataclass

from host_sdk.errors import RoverLinkError
from host_sdk.session.requests import Request
from host_sdk.session.types import FeedbackSample, RobotIdentity
from protocol.generated.enums import FailsafeReason, LogLevel


@dataclass(frozen=True, slots=True)
class Opened:
    identity: RobotIdentity
    reconnect: bool
    """True when this session replaces one that a reset ended."""


@dataclass(frozen=True, slots=True)
class Ready:
    """Identity and configuration are known: the robot can be used."""


@dataclass(frozen=True, slots=True)
class ResetDetected:
    old_boot_id: int
    new_boot_id: int | None
    why: str


@dataclass(frozen=True, slots=True)
class FeedbackReceived:
    sample: FeedbackSample


@dataclass(frozen=True, slots=True)
class LogReceived:
    level: LogLevel
    text: str


@dataclass(frozen=True, slots=True)
class FailsafeEntered:
    reason: FailsafeReason
    predicted: bool
    """True when the host inferred it (it stopped sending for a watchdog period) before the board said so."""


@dataclass(frozen=True, slots=True)
class Failed:
    error: RoverLinkError


@dataclass(frozen=True, slots=True)
class RequestFinished:
    request: Request


Event = Opened | Ready | ResetDetected | FeedbackReceived | LogReceived | FailsafeEntered | Failed | RequestFinished
