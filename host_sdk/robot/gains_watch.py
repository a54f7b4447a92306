"""A warning when new PID gains make a wheel's loop oscillate with the drive saturated.

The board accepts any gains within the spec's ranges: it cannot know the motor. Gains far too high
(kp=ki=500 on a small gearmotor) make the wheel speed swing round its setpoint with the effort
banging between its limits, which FEEDBACK shows only as a SATURATED bit. After `set_pid` the
robot watches FEEDBACK for `WINDOW_S` of driving and warns once (`PidGainsWarning`, a
UserWarning, also logged) when a wheel's speed swings by more than `SWING_FRACTION` of its mean
while its effort is at a limit in more than `SATURATED_FRACTION` of the samples. A wheel that is
merely asked for more than its motor gives saturates without swinging: the gains are not blamed.
"""

from __future__ import annotations

import logging
import statistics
import warnings
from collections.abc import Callable

from host_sdk.session import FeedbackSample

WINDOW_S = 1.5
"""How long a window of driving (|speed| >= MIN_SPEED_M_S) is judged after new gains."""
MIN_SPEED_M_S = 0.05
SWING_FRACTION = 0.25
"""Peak to peak (5th to 95th percentile) of the speed, as a share of its mean."""
SATURATED_FRACTION = 0.25
AT_LIMIT = 0.98
"""|effort| at or above this is the drive saturated."""
_log = logging.getLogger("host_sdk")


class PidGainsWarning(UserWarning):
    """New PID gains made a wheel oscillate with its drive saturated; the text says by how much."""


class GainsWatch:
    """Fed every FEEDBACK after new gains; calls `warn(text)` at most once, then `done()`."""

    def __init__(self, gains: str, warn: Callable[[str], None] = lambda text: None) -> None:
        self.gains = gains
        self._warn = warn
        self._speeds: list[list[float]] = []
        self._saturated: list[int] = []
        self._count = 0
        self._start_s: float | None = None
        self.finished = False
        self.verdict: str | None = None

    def feed(self, sample: FeedbackSample) -> None:
        if self.finished:
            return
        speeds = sample.wheel_speeds_m_s
        if not speeds or max(abs(v) for v in speeds) < MIN_SPEED_M_S:
            return  # standing (or creeping) tells nothing about the loop
        if self._start_s is None:
            self._start_s = sample.host_time_s
            self._speeds = [[] for _ in speeds]
            self._saturated = [0] * len(speeds)
        self._count += 1
        for i, (v, effort) in enumerate(zip(speeds, sample.efforts, strict=False)):
            self._speeds[i].append(v)
            self._saturated[i] += abs(effort) >= AT_LIMIT
        if sample.host_time_s - self._start_s >= WINDOW_S:
            self.finished = True
            self.verdict = self._judge()
            if self.verdict is not None:
                self._warn(self.verdict)

    def _judge(self) -> str | None:
        for i, series in enumerate(self._speeds):
            if len(series) < 10:
                continue
            cuts = statistics.quantiles(series, n=20)
            low, high, mean = cuts[0], cuts[-1], statistics.fmean(series)
            saturated = self._saturated[i] / self._count
            if (
                abs(mean) >= MIN_SPEED_M_S
                and high - low > SWING_FRACTION * abs(mean)
                and saturated > SATURATED_FRACTION
            ):
                return (
                    f"PID gains {self.gains} make wheel {i} oscillate: its speed swings {low:.2f}..{high:.2f} m/s "
                    f"around {mean:.2f} with the drive saturated {100 * saturated:.0f} % of the time; lower kp and ki "
                    "(`roverlink tune` measures the wheel and finds gains that do not)"
                )
        return None


def warn_about_gains(text: str) -> None:
    """The warning as a robot program sees it: a PidGainsWarning, and a line in the log."""
    _log.warning("%s", text)
    warnings.warn(PidGainsWarning(text), stacklevel=2)
