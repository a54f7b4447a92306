"""One exception tree for the whole SDK.

Every error is a `RoverLinkError` (the root lives with the codec in protocol.errors, so the
codec's and the emulator's errors share it); each leaf also inherits the built-in it behaves
like, so `except ValueError` or `except TimeoutError` in user code keeps working.
"""

from __future__ import annotations

from protocol.errors import ArgumentError, ArgumentTypeError, CodecError, DecodeError, EncodeError, RoverLinkError

__all__ = [
    "ArgumentError",
    "ArgumentTypeError",
    "CodecError",
    "CommandRangeError",
    "ConnectTimeoutError",
    "DecodeError",
    "EncodeError",
    "FailsafeError",
    "FeedbackTimeoutError",
    "IncompatibleFirmwareError",
    "KinematicsError",
    "LinkBrokenError",
    "NackError",
    "NotArmedError",
    "RealtimeError",
    "RequestTimeoutError",
    "RobotClosedError",
    "RoverLinkError",
    "SessionResetError",
    "TransportError",
    "UnsupportedError",
]


# -- session and robot errors -----------------------------------------------------------------------
class TransportError(RoverLinkError, OSError):
    """The port could not be opened, or failed while in use (unplugged, closed by the OS).

    `url` names the port; `cause` is the underlying exception, if any.
    """

    def __init__(self, message: str, url: str = "", cause: BaseException | None = None) -> None:
        self.url = url
        self.cause = cause
        super().__init__(message)


class ConnectTimeoutError(RoverLinkError, TimeoutError):
    """No session could be opened in time.

    Attributes: `url`, `baud`, `timeout_s`, and what was heard: `bytes_received`, `frames_ok`
    (valid frames of any kind) and `identity_seen` (an IDENTITY arrived but never one answering
    this host's HELLO). The message says what to check.
    """

    def __init__(
        self, url: str, baud: int, timeout_s: float, *, bytes_received: int, frames_ok: int, identity_seen: bool
    ) -> None:
        self.url = url
        self.baud = baud
        self.timeout_s = timeout_s
        self.bytes_received = bytes_received
        self.frames_ok = frames_ok
        self.identity_seen = identity_seen
        if bytes_received == 0:
            seen = "nothing at all was received: check the cable, the port name and that the board has power"
        elif frames_ok == 0:
            seen = (
                f"{bytes_received} bytes arrived but not one valid RoverLink frame: check the baud rate "
                f"(the firmware's Serial.begin) and that the board runs RoverLink firmware"
            )
        else:
            seen = (
                f"{frames_ok} valid frames arrived but no answer to HELLO"
                + (" (the board announced itself)" if identity_seen else "")
                + ": the firmware may be busy or the host-to-board direction is broken (check TX wiring)"
            )
        super().__init__(f"no RoverLink session on {url} at {baud} baud within {timeout_s:g} s; {seen}")


class RequestTimeoutError(RoverLinkError, TimeoutError):
    """A reliable request got no answer after every retry. Attributes: `request`, `tries`, `timeout_s`."""

    def __init__(self, request: str, tries: int, timeout_s: float) -> None:
        self.request = request
        self.tries = tries
        self.timeout_s = timeout_s
        super().__init__(
            f"{request}: no answer after {tries} tries ({timeout_s:g} s each); the link may be cut or the board hung"
        )


class IncompatibleFirmwareError(RoverLinkError):
    """The firmware was built from another protocol version or spec than this SDK.

    Attributes: `url`, the firmware's `firmware_version`/`firmware_hash`, the SDK's `sdk_version`/`sdk_hash`,
    `robot_name` (the firmware example, if it said).
    """

    def __init__(
        self,
        url: str,
        firmware_version: int,
        firmware_hash: int,
        sdk_version: int,
        sdk_hash: int,
        *,
        robot_name: str = "",
    ) -> None:
        self.url = url
        self.firmware_version = firmware_version
        self.firmware_hash = firmware_hash
        self.sdk_version = sdk_version
        self.sdk_hash = sdk_hash
        self.robot_name = robot_name
        example = robot_name or "<YourExample>"
        port = url if url.startswith("/dev/") else "<port>"
        super().__init__(
            f"incompatible firmware on {url}: it speaks protocol v{firmware_version} with spec hash "
            f"0x{firmware_hash:08X}, this SDK protocol v{sdk_version} with spec hash 0x{sdk_hash:08X}. "
            f"Re-flash the board with firmware built from this SDK's spec: "
            f"`roverlink firmware flash --example {example} --port {port}` "
            f"(or install the SDK version the firmware was built with)"
        )


class NackError(RoverLinkError):
    """The board refused a request. Attributes: `request` (message name), `reason` (NackReason),
    `detail` (raw detail byte) and `field` (the field's name when the detail is a field index)."""

    def __init__(self, request: str, reason: object, detail: int, field: str | None = None, hint: str = "") -> None:
        self.request = request
        self.reason = reason
        self.detail = detail
        self.field = field
        name = getattr(reason, "name", str(reason))
        where = f" (field {field})" if field else (f" (detail {detail})" if detail else "")
        super().__init__(f"{request} refused by the board: {name}{where}" + (f"; {hint}" if hint else ""))


class SessionResetError(RoverLinkError):
    """The board was reset (new boot_id): the robot is disarmed and the session was re-opened.

    Attributes: `old_boot_id`, `new_boot_id` (None while the new boot is not yet known).
    Re-arm with `robot.arm()` when it is safe to drive again.
    """

    def __init__(self, old_boot_id: int, new_boot_id: int | None, detail: str = "") -> None:
        self.old_boot_id = old_boot_id
        self.new_boot_id = new_boot_id
        new = f"0x{new_boot_id:08X}" if new_boot_id is not None else "unknown yet"
        super().__init__(
            f"the board was reset (boot_id 0x{old_boot_id:08X} -> {new}){': ' + detail if detail else ''}; "
            f"the robot is disarmed and commands of the old session are void: call robot.arm() to drive again"
        )


class NotArmedError(RoverLinkError, RuntimeError):
    """A drive command while the robot is not armed. Attribute `state` says what the robot is in."""

    def __init__(self, message: str, state: str) -> None:
        self.state = state
        super().__init__(message)


class FailsafeError(NotArmedError):
    """A drive command while the firmware holds a latched FAILSAFE. Attribute `reason` (FailsafeReason)."""

    def __init__(self, reason: object, hint: str = "") -> None:
        self.reason = reason
        name = getattr(reason, "name", str(reason))
        super().__init__(
            f"the robot is in FAILSAFE ({name}){'; ' + hint if hint else ''}; call robot.arm() to drive again",
            "FAILSAFE",
        )


class UnsupportedError(RoverLinkError, RuntimeError):
    """This robot cannot do that (e.g. drive_ackermann on a differential drive).

    `capability` is the firmware capability (enums.Capability) that is missing, when one is.
    """

    def __init__(self, message: str, capability: object | None = None) -> None:
        self.capability = capability
        super().__init__(message)


class LinkBrokenError(RoverLinkError, RuntimeError):
    """The robot's link stopped for an unexpected reason (an error in a layer below, a failing
    plugin transport): the robot is unusable. `cause` (also `__cause__`) is what went wrong; close
    the robot and connect again."""

    def __init__(self, url: str, cause: BaseException) -> None:
        self.url = url
        self.cause = cause
        super().__init__(
            f"the link to {url or 'the robot'} stopped: {type(cause).__name__}: {cause}; "
            "the robot is unusable: close it and connect again"
        )
        self.__cause__ = cause


class RobotClosedError(RoverLinkError, RuntimeError):
    """A call on a robot after close()."""

    def __init__(self, url: str = "") -> None:
        self.url = url
        super().__init__(f"the robot on {url or 'this link'} is closed: connect again with Robot.connect()")


class RealtimeError(RoverLinkError, PermissionError):
    """Real-time scheduling was asked for and the system does not allow it (host_sdk.hostinfo.realtime)."""


class CommandRangeError(ArgumentError):
    """A bad argument from user code: NaN, infinity, beyond the robot's limits, an unknown field.

    Attributes: `argument`, `value`, `allowed` (human-readable range). An argument of the wrong
    type raises its sibling `ArgumentTypeError` (also a TypeError); `ArgumentError` catches both.
    """


class KinematicsError(CommandRangeError):
    """A kinematic request that cannot be met (e.g. a turn tighter than the steering allows)."""


class FeedbackTimeoutError(RoverLinkError, TimeoutError):
    """No FEEDBACK arrived in time. Attributes: `timeout_s`, `lockstep`, `waited_s`."""

    def __init__(
        self,
        timeout_s: float,
        lockstep: bool = False,
        command_live: bool = True,
        *,
        armed: bool = True,
        waited_s: float | None = None,
    ) -> None:
        self.timeout_s = timeout_s
        self.lockstep = lockstep
        self.waited_s = timeout_s if waited_s is None else waited_s
        """How long it waited: longer than `timeout_s` when the silence was young enough to be a reset."""
        hint = (
            "in lockstep mode an armed board sends FEEDBACK only in answer to a setpoint: drive first"
            if lockstep and armed and not command_live
            else "the link may be cut or the board stopped"
        )
        longer = ""
        if self.waited_s > timeout_s:
            longer = f" (waited {self.waited_s:.2g} s: a board that falls silent may be rebooting)"
        super().__init__(f"no FEEDBACK within {timeout_s:g} s{longer}; {hint}")
