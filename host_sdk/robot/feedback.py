"""`Feedback`, the part of a Robot that reads: the next FEEDBACK, a stream of them, and the callbacks.

A board reset is reported once, as SessionResetError, by whichever call meets it first; the
bootloader's silence before the new boot announces itself is part of it (docs/sdk.md, "Resets"):
a wait for FEEDBACK that meets a silence younger than `reset_silence_s` waits it out instead of
raising FeedbackTimeoutError, and ends with the reset when the new boot announces itself.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

from host_sdk import checks
from host_sdk.errors import FeedbackTimeoutError, RobotClosedError
from host_sdk.robot.callbacks import (
    FailsafeCallback,
    FeedbackCallback,
    LogCallback,
    OdometryGapCallback,
    ResetCallback,
)
from host_sdk.robot.link import Link
from host_sdk.session import FeedbackSample
from protocol.generated.enums import FeedbackMode


class Feedback:
    """Keeps nothing of its own: FEEDBACK lives in the session, the callbacks in the link."""

    def __init__(self, link: Link) -> None:
        self._link = link

    def wait_feedback(self, timeout_s: float = 1.0) -> FeedbackSample:
        """The next FEEDBACK. In lockstep mode while armed: the one answering the latest drive
        command (a lockstep board streams at feedback_hz while it is not armed, as in stream mode).

        Raises SessionResetError (once) if the board was reset, FeedbackTimeoutError (a
        TimeoutError) if none arrives within `timeout_s`. A board that went silent less than
        `reset_silence_s` (2 s) ago may be rebooting: the wait then goes on until that silence is
        over, and raises SessionResetError if it ends in a new boot."""
        return self.next(checks.seconds("timeout_s", timeout_s), report_reset=True)

    def feedback_stream(self, timeout_s: float = 1.0) -> Iterator[FeedbackSample]:
        """Yield FEEDBACK samples as they arrive, until the robot is closed. It goes on across a
        board reset (the reset is left to the next drive call, wait_feedback, arm or request).

        A slow consumer sees the latest sample (some are skipped); use `on_feedback` to see every one."""
        timeout = checks.seconds("timeout_s", timeout_s)

        def samples() -> Iterator[FeedbackSample]:
            while not self._link.closed:
                try:
                    yield self.next(timeout, report_reset=False)
                except RobotClosedError:
                    return

        return samples()

    def next(self, timeout: float, report_reset: bool) -> FeedbackSample:
        """The next FEEDBACK (see wait_feedback); `report_reset`: raise a reset not yet reported."""
        link = self._link
        runner, s = link.runner, link.session
        with link.lock:
            runner.check()
            self._report_reset(report_reset)
            start = s.latest.index if s.latest is not None else 0
            lockstep = s.feedback_mode is FeedbackMode.LOCKSTEP
            armed = s.armed
            live = s.setpoint_live  # at the start: one that expires while waiting is no "drive first"
            want = link.last_command_seq if lockstep and armed and live else None
            # Lockstep while armed: only a command is answered. Otherwise the board streams.
            owed = not (lockstep and armed) or want is not None

        def fresh() -> FeedbackSample | None:
            sample = s.latest
            if sample is None or sample.index <= start:
                return None
            return sample if want is None or (sample.ack_seq - want) % 256 < 128 else None

        def arrived() -> bool:
            return fresh() is not None or (report_reset and s.reset_pending) or runner.broken()

        left = 0.0
        if not runner.wait(arrived, timeout) and owed:
            with link.lock:
                now = link.clock()
                until = s.silence_deadline(now)
                left = 0.0 if until is None else until - now
            if left > 0:
                runner.wait(arrived, left)  # the silence may be a reset: wait for its announcement
        with link.lock:
            runner.check()
            self._report_reset(report_reset)
            sample = fresh()
            if sample is None:
                waited = timeout + max(left, 0.0)
                raise FeedbackTimeoutError(timeout, lockstep, live, armed=armed, waited_s=waited)
            return sample

    def _report_reset(self, report: bool) -> None:
        """Raise the reset not yet reported (lock held), once."""
        error = self._link.session.take_reset() if report else None
        if error is not None:
            raise error

    # == callbacks ===================================================================================
    def on_feedback(self, callback: FeedbackCallback) -> Callable[[], None]:
        """Call `callback(sample)` for every FEEDBACK (on the I/O thread). Returns a function that unsubscribes."""
        return self._link.callbacks.subscribe("feedback", callback)

    def on_reset(self, callback: ResetCallback) -> Callable[[], None]:
        """Call `callback(SessionResetError)` when a board reset is detected (it does not count as
        reporting it: the next call still raises it)."""
        return self._link.callbacks.subscribe("reset", callback)

    def on_odometry_gap(self, callback: OdometryGapCallback) -> Callable[[], None]:
        """Call `callback(OdometryGap)` when encoder counts were lost (a board reset): how long, and
        how much the pose's uncertainty grew."""
        return self._link.callbacks.subscribe("odometry_gap", callback)

    def on_failsafe(self, callback: FailsafeCallback) -> Callable[[], None]:
        """Call `callback(reason)` when the board enters FAILSAFE (or the host knows it must have)."""
        return self._link.callbacks.subscribe("failsafe", callback)

    def on_log(self, callback: LogCallback) -> Callable[[], None]:
        """Call `callback(level, text)` for every LOG frame of the firmware (they also go to logging)."""
        return self._link.callbacks.subscribe("log", callback)
