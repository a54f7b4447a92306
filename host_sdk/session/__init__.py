"""The sans-I/O session (see core.py) and the snapshots it hands out."""

from host_sdk.session.core import (
    Event,
    Failed,
    FailsafeEntered,
    FeedbackReceived,
    LinkState,
    LogReceived,
    Opened,
    Ready,
    Request,
    RequestFinished,
    ResetDetected,
    Session,
    SessionOptions,
)
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
