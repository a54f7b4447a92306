"""The sans-I/O session (see core.py) and the snapshots it hands out."""

from host_sdk.session.core import Session
from host_sdk.session.events import (
    Event,
    Failed,
    FailsafeEntered,
    FeedbackReceived,
    LogReceived,
    OdometryGap,
    Opened,
    Ready,
    RequestFinished,
    ResetDetected,
)
from host_sdk.session.options import LinkState, SessionOptions
from host_sdk.session.requests import Request
from host_sdk.session.types import (
    FeedbackSample,
    LinkStatistics,
    PidGains,
    RobotConfig,
    RobotIdentity,
    RttStats,
)

__all__ = [
    "Event",
    "Failed",
    "FailsafeEntered",
    "FeedbackReceived",
    "FeedbackSample",
    "LinkState",
    "LinkStatistics",
    "LogReceived",
    "OdometryGap",
    "Opened",
    "PidGains",
    "Ready",
    "Request",
    "RequestFinished",
    "ResetDetected",
    "RobotConfig",
    "RobotIdentity",
    "RttStats",
    "Session",
    "SessionOptions",
]
