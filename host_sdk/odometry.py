"""Pose from cumulative encoder counts stamped with MCU time.

Counts are cumulative on the MCU, so a lost FEEDBACK frame loses no ticks: the next one carries
them, and the motion between the two is integrated as one constant-curvature arc. Counts are i32
on the wire and wrap; MCU time is u32 microseconds and wraps every 71.6 minutes; both are unwrapped
here. Integration is exact for constant-curvature segments.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from host_sdk.kinematics import Ackermann, Arc, DiffDrive

_I32 = 1 << 32


def wrap_delta_i32(new: int, old: int) -> int:
    """Signed difference of two i32 counters, correct across a wrap (|true delta| < 2**31)."""
    d = (new - old) % _I32
    return d - _I32 if d >= 1 << 31 else d


def integrate_arc(x: float, y: float, theta: float, arc: Arc) -> tuple[float, float, float]:
    """Pose after moving along `arc` from (x, y, theta): exact for constant curvature."""
    ds, dth = arc.distance_m, arc.dtheta_rad
    # The chord of an arc is ds * sinc(dth/2) long and points along the mid-arc heading. Written
    # this way it is exact and has no 1/dth cancellation as the curvature goes to zero.
    half = dth / 2
    chord = ds * (math.sin(half) / half if abs(half) > 1e-6 else 1.0 - half * half / 6)
    mid = theta + half
    return x + chord * math.cos(mid), y + chord * math.sin(mid), theta + dth


@dataclass(frozen=True, slots=True)
class Pose:
    x_m: float
    y_m: float
    theta_rad: float
    """Heading, unwrapped (keeps counting past +-pi so turns can be totalled)."""
    linear_m_s: float
    angular_rad_s: float
    mcu_time_us: int
    """Unwrapped MCU time of the latest sample (0 before the first)."""

    @property
    def heading_rad(self) -> float:
        """Heading wrapped to (-pi, pi]."""
        return math.atan2(math.sin(self.theta_rad), math.cos(self.theta_rad))


class Odometry:
    """Integrates samples of (cumulative counts, MCU time[, steering]) into a pose.

    Not thread-safe by itself; the session calls `update` from its I/O thread under its lock.
    """

    def __init__(self, kinematics: DiffDrive | Ackermann) -> None:
        self.kinematics = kinematics
        self.reset()

    def reset(self, x_m: float = 0.0, y_m: float = 0.0, theta_rad: float = 0.0) -> None:
        """Set the pose; the next sample only re-anchors the counts (no motion is integrated)."""
        self._x, self._y, self._theta = x_m, y_m, theta_rad
        self._v = self._w = 0.0
        self._counts: tuple[int, ...] | None = None
        self._time_raw: int | None = None
        self._time_us = 0

    def update(self, counts: Sequence[int], mcu_time_us: int, steering_rad: float = 0.0) -> Pose:
        """Add one sample. `counts` are the cumulative raw wheel counts as on the wire (i32),
        `mcu_time_us` the u32 MCU timestamp, `steering_rad` the Ackermann angle held since the
        previous sample."""
        dt_us = 0 if self._time_raw is None else (mcu_time_us - self._time_raw) % (1 << 32)
        self._time_raw = mcu_time_us
        self._time_us += dt_us
        counts = tuple(counts)
        if self._counts is not None:
            deltas = [wrap_delta_i32(n, o) for n, o in zip(counts, self._counts, strict=True)]
            arc = (
                self.kinematics.arc(deltas[0], deltas[1])
                if isinstance(self.kinematics, DiffDrive)
                else self.kinematics.arc(deltas[0], steering_rad)
            )
            self._x, self._y, self._theta = integrate_arc(self._x, self._y, self._theta, arc)
            if dt_us > 0:
                self._v, self._w = arc.distance_m * 1e6 / dt_us, arc.dtheta_rad * 1e6 / dt_us
        self._counts = counts
        return self.pose

    @property
    def pose(self) -> Pose:
        return Pose(self._x, self._y, self._theta, self._v, self._w, self._time_us)
