"""The robot's callbacks (`on_feedback`, `on_reset`, `on_odometry_gap`, `on_failsafe`, `on_log`) and
their delivery."""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any

from host_sdk import checks
from host_sdk.errors import SessionResetError
from host_sdk.session import (
    Event,
    Failed,
    FailsafeEntered,
    FeedbackReceived,
    FeedbackSample,
    LogReceived,
    OdometryGap,
    ResetDetected,
)
from protocol.generated.enums import FailsafeReason, LogLevel

log = logging.getLogger("host_sdk")

FeedbackCallback = Callable[[FeedbackSample], None]
ResetCallback = Callable[[SessionResetError], None]
OdometryGapCallback = Callable[[OdometryGap], None]
FailsafeCallback = Callable[[FailsafeReason], None]
LogCallback = Callable[[LogLevel, str], None]

_LOG_LEVELS = {
    LogLevel.DEBUG: logging.DEBUG,
    LogLevel.INFO: logging.INFO,
    LogLevel.WARN: logging.WARNING,
    LogLevel.ERROR: logging.ERROR,
}


class Callbacks:
    """Subscribers per kind of event; `dispatch(events)` calls them (an exception in one is logged)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.feedback: tuple[FeedbackCallback, ...] = ()
        self.reset: tuple[ResetCallback, ...] = ()
        self.odometry_gap: tuple[OdometryGapCallback, ...] = ()
        self.failsafe: tuple[FailsafeCallback, ...] = ()
        self.log: tuple[LogCallback, ...] = ()

    def subscribe(self, kind: str, callback: Any) -> Callable[[], None]:
        """Add `callback` to `kind`'s subscribers; returns the function that removes it again."""
        checks.callback("callback", callback)
        with self._lock:  # tuples, replaced whole: dispatch reads them without a lock
            setattr(self, kind, (*getattr(self, kind), callback))

        def unsubscribe() -> None:
            with self._lock:
                now = list(getattr(self, kind))
                if callback in now:
                    now.remove(callback)
                    setattr(self, kind, tuple(now))

        return unsubscribe

    def dispatch(self, events: list[Event]) -> None:
        for event in events:
            try:
                if isinstance(event, FeedbackReceived):
                    for fb_cb in self.feedback:
                        fb_cb(event.sample)
                elif isinstance(event, ResetDetected):
                    error = SessionResetError(event.old_boot_id, event.new_boot_id, event.why)
                    for reset_cb in self.reset:
                        reset_cb(error)
                elif isinstance(event, OdometryGap):
                    for gap_cb in self.odometry_gap:
                        gap_cb(event)
                elif isinstance(event, FailsafeEntered):
                    for fs_cb in self.failsafe:
                        fs_cb(event.reason)
                elif isinstance(event, LogReceived):
                    log.log(_LOG_LEVELS.get(event.level, logging.INFO), "board: %s", event.text)
                    for log_cb in self.log:
                        log_cb(event.level, event.text)
                elif isinstance(event, Failed):
                    log.error("RoverLink session failed: %s", event.error)
            except Exception:
                log.exception("a RoverLink callback raised (ignored)")
