"""`Robot.connect`'s keyword arguments, checked, as the session's options."""

from __future__ import annotations

from host_sdk import checks
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.profiles import get_profile
from host_sdk.session import SessionOptions
from host_sdk.transport import Transport
from protocol.generated.constants import FEEDBACK_HZ_MAX, WATCHDOG_MAX_MS, WATCHDOG_MIN_MS
from protocol.generated.enums import FeedbackMode

BAUD_RANGE = (50, 4_000_000)
"""Line speeds a serial port may be opened at (bit/s)."""
MAX_REQUEST_TIMEOUT_S = 60.0
MAX_REQUEST_TRIES = 100


def check_connect(
    url: object,
    *,
    profile: object,
    kinematics: object,
    baud: object,
    watchdog_s: object,
    mode: object,
    feedback_hz: object,
    timeout_s: object,
    clamp: object,
    auto_rearm: object,
    paced: object,
    command_timeout_s: object,
    request_timeout_s: object,
    request_tries: object,
    transport: object,
) -> SessionOptions:
    """Every argument of `Robot.connect`, checked (ArgumentError names the first bad one), as the
    session's options."""
    if transport is None:
        checks.text("url", url, allowed="a port or URL str: /dev/ttyACM0, COM3, socket://host:port, emu://...")
    else:
        checks.instance("transport", transport, Transport, "a host_sdk.transport.Transport, or None")
    if profile is not None:
        get_profile(profile, argument="profile")  # type: ignore[arg-type]  # checks it
    checks.optional(
        checks.instance, "kinematics", kinematics, (DiffDrive, Ackermann), "a DiffDrive, an Ackermann or None"
    )
    baud_ = checks.integer("baud", baud, *BAUD_RANGE, what="a line speed in bit/s")
    watchdog = checks.number("watchdog_s", watchdog_s, WATCHDOG_MIN_MS / 1000, WATCHDOG_MAX_MS / 1000, unit="s")
    mode_ = checks.choice("mode", mode, ("stream", "lockstep"))
    rate = checks.integer("feedback_hz", feedback_hz, 0, FEEDBACK_HZ_MAX, what="a rate in Hz (0: the board's default)")
    checks.seconds("timeout_s", timeout_s)
    checks.flag("clamp", clamp)
    rearm = checks.flag("auto_rearm", auto_rearm)
    paced_ = checks.flag("paced", paced)
    command_timeout = checks.optional(checks.seconds, "command_timeout_s", command_timeout_s)
    request_timeout = checks.seconds("request_timeout_s", request_timeout_s, hi=MAX_REQUEST_TIMEOUT_S)
    tries = checks.integer("request_tries", request_tries, 1, MAX_REQUEST_TRIES, what="a number of tries")
    return SessionOptions(
        watchdog_s=watchdog,
        feedback_mode=FeedbackMode.LOCKSTEP if mode_ == "lockstep" else FeedbackMode.STREAM,
        feedback_hz=rate,
        request_timeout_s=request_timeout,
        request_tries=tries,
        command_timeout_s=command_timeout,
        auto_rearm=rearm,
        paced=paced_,
        url=transport.url if isinstance(transport, Transport) else str(url),
        baud=baud_,
    )
