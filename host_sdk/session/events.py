"""What the session reports (`Session.take_events()`)."""

from __future__ import annotations

from dataclasses import dataclass

from host_sdk.errors import RoverLinkError
from host_sdk.pose import Pose
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
class OdometryGap:
    """Encoder counts were lost: the board was reset, and what the wheels turned between its last
    FEEDBACK and its reboot is not counted. The pose is kept; its uncertainty grew."""

    duration_s: float
    """Time without counts: from the last FEEDBACK of the old boot to the reset being known."""
    position_m: float
    """What the position uncertainty grew by: the speed at the last sample times `duration_s`."""
    heading_rad: float
    """What the heading uncertainty grew by: the turn rate at the last sample times `duration_s`."""
    pose: Pose
    """The pose now, with its `gaps` count and uncertainty."""


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


Event = (
    Opened
    | Ready
    | ResetDetected
    | OdometryGap
    | FeedbackReceived
    | LogReceived
    | FailsafeEntered
    | Failed
    | RequestFinished
)
