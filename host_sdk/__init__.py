"""RoverLink host SDK: talk to a RoverLink robot (board, simulator or emulator) from Python.

    >>> from host_sdk import Robot
    >>> with Robot.connect("emu://?clock=virtual") as robot:  # or "/dev/ttyACM0", "socket://host:port", ...
    ...     robot.arm()
    ...     for _ in range(50):  # about a second: FEEDBACK comes at 50 Hz
    ...         robot.drive(0.2, 0.0)
    ...         sample = robot.wait_feedback()
    ...     print(f"{sample.pose.x_m:.1f} m")
    0.2 m

See docs/sdk.md.
"""

from typing import TYPE_CHECKING, Any

from host_sdk import enums, messages
from host_sdk.errors import (
    ArgumentError,
    ArgumentTypeError,
    CodecError,
    CommandRangeError,
    ConnectTimeoutError,
    DecodeError,
    EncodeError,
    FailsafeError,
    FeedbackTimeoutError,
    IncompatibleFirmwareError,
    KinematicsError,
    LinkBrokenError,
    NackError,
    NotArmedError,
    RealtimeError,
    RequestTimeoutError,
    RobotClosedError,
    RoverLinkError,
    SessionResetError,
    TransportError,
    UnsupportedError,
)
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.lights import LightsStatus
from host_sdk.pose import Pose
from host_sdk.profiles import PROFILES, kinematics_for
from host_sdk.robot import Robot
from host_sdk.robot.file_check import Mismatch, RobotMismatchError
from host_sdk.robot.gains_watch import PidGainsWarning
from host_sdk.robot_description import RobotDescription, RobotFileError
from host_sdk.session import FeedbackSample, LinkStatistics, PidGains, RobotConfig, RobotIdentity
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH
from protocol.generated.version import __version__ as release_version

__all__ = [
    "PROFILES",
    "PROTOCOL_VERSION",
    "SPEC_HASH",
    "Ackermann",
    "ArgumentError",
    "ArgumentTypeError",
    "AsyncRobot",
    "CodecError",
    "CommandRangeError",
    "ConnectTimeoutError",
    "DecodeError",
    "DiffDrive",
    "EncodeError",
    "FailsafeError",
    "FeedbackSample",
    "FeedbackStream",
    "FeedbackTimeoutError",
    "IncompatibleFirmwareError",
    "KinematicsError",
    "LightsStatus",
    "LinkBrokenError",
    "LinkStatistics",
    "Mismatch",
    "NackError",
    "NotArmedError",
    "PidGains",
    "PidGainsWarning",
    "Pose",
    "RealtimeError",
    "RequestTimeoutError",
    "Robot",
    "RobotClosedError",
    "RobotConfig",
    "RobotDescription",
    "RobotFileError",
    "RobotIdentity",
    "RobotMismatchError",
    "RoverLinkError",
    "SessionResetError",
    "TransportError",
    "UnsupportedError",
    "enums",
    "kinematics_for",
    "messages",
]
__version__ = release_version

if TYPE_CHECKING:
    from host_sdk.aio import AsyncRobot, FeedbackStream


def __getattr__(name: str) -> Any:
    # asyncio is imported only by programs that use it: `import host_sdk` stays small on a Pi.
    if name in ("AsyncRobot", "FeedbackStream"):
        from host_sdk import aio  # noqa: PLC0415

        return getattr(aio, name)
    raise AttributeError(f"module 'host_sdk' has no attribute {name!r}")
