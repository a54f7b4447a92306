"""Pose from cumulative encoder counts stamped with MCU time.

Counts are cumulative on the MCU, so a lost FEEDBACK frame loses no ticks: the next one carries
them, and the motion between the two is integrated as one constant-curvature arc. Integration is
exact for constant-curvature segments. Counts and MCU time come in unwrapped (the session unwraps
the wire's i32 counts and u32 microseconds with host_sdk.timesync.Unwrapper, the one place that
does): here they are plain, ever-growing ints.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from host_sdk import checks
from host_sdk.errors import ArgumentTypeError
from host_sdk.kinematics import MAX_RATE, Ackermann, Arc, DiffDrive
from host_sdk.pose import Pose

MAX_POSITION_M = 1e9
"""Largest |x|, |y| or |theta| a pose may be set to (beyond it the arc maths loses all precision)."""


def integrate_arc(x: float, y: float, theta: float, arc: Arc) -> tuple[float, float, float]:
    """Pose after moving along `arc` from (x, y, theta): exact for constant curvature."""
    x = _coordinate("x", x)
    y = _coordinate("y", y)
    theta = _coordinate("theta", theta)
    arc = checks.instance("arc", arc, Arc, "an Arc")
    checks.number("arc.distance_m", arc.distance_m, -MAX_POSITION_M, MAX_POSITION_M, unit="m")
    checks.number("arc.dtheta_rad", arc.dtheta_rad, -MAX_RATE, MAX_RATE, unit="rad")
    return _integrate(x, y, theta, arc.distance_m, arc.dtheta_rad)


def _integrate(x: float, y: float, theta: float, ds: float, dth: float) -> tuple[float, float, float]:
    # The chord of an arc is ds * sinc(dth/2) long and points along the mid-arc heading. Written
    # this way it is exact and has no 1/dth cancellation as the curvature goes to zero.
    half = dth / 2
    chord = ds * (math.sin(half) / half if abs(half) > 1e-6 else 1.0 - half * half / 6)
    mid = theta + half
    return x + chord * math.cos(mid), y + chord * math.sin(mid), theta + dth


def _coordinate(name: str, value: object) -> float:
    return checks.number(name, value, -MAX_POSITION_M, MAX_POSITION_M)


class Odometry:
    """Integrates samples of (cumulative counts, MCU time[, steering]) into a pose.

    Not thread-safe by itself; the session calls `update` from its I/O thread under its lock.
    """

    __slots__ = (
        "_counts",
        "_gaps",
        "_heading_unc",
        "_host_s",
        "_position_unc",
        "_theta",
        "_time_us",
        "_v",
        "_w",
        "_wheels",
        "_x",
        "_y",
        "kinematics",
    )

    def __init__(self, kinematics: DiffDrive | Ackermann) -> None:
        checks.instance("kinematics", kinematics, (DiffDrive, Ackermann), "a DiffDrive or Ackermann")
        self.kinematics = kinematics
        self._wheels = 2 if isinstance(kinematics, DiffDrive) else 1
        self.reset()

    def reset(self, x_m: float = 0.0, y_m: float = 0.0, theta_rad: float = 0.0) -> None:
        """Set the pose (known again: no gap, no uncertainty); the next sample only re-anchors the
        counts (no motion is integrated)."""
        self._x, self._y, self._theta = (
            _coordinate("x_m", x_m),
            _coordinate("y_m", y_m),
            _coordinate("theta_rad", theta_rad),
        )
        self._gaps = 0
        self._position_unc = self._heading_unc = 0.0
        self.reanchor()

    def reanchor(self) -> None:
        """The counts start again (a new boot): the pose, its gaps and uncertainty are kept, the
        next sample only re-anchors the counts."""
        self._v = self._w = 0.0
        self._counts: Sequence[int] | None = None
        self._time_us: int | None = None
        self._host_s = 0.0

    def restore(self, pose: Pose) -> None:
        """Carry on from `pose` (its gaps and uncertainty too), e.g. with new kinematics."""
        self.reset(pose.x_m, pose.y_m, pose.theta_rad)
        self._gaps = pose.gaps
        self._position_unc, self._heading_unc = pose.position_uncertainty_m, pose.heading_uncertainty_rad

    def gap(self, duration_s: float) -> tuple[float, float]:
        """Counts were lost for `duration_s` (a board reset): the pose is kept, its uncertainty grows
        by what the robot would have moved going on at its last measured speed and turn rate, and
        the counts re-anchor on the next sample. Returns that (position m, heading rad)."""
        lost_m, lost_rad = abs(self._v) * duration_s, abs(self._w) * duration_s
        self._gaps += 1
        self._position_unc += lost_m
        self._heading_unc += lost_rad
        self.reanchor()
        return lost_m, lost_rad

    def update(self, counts: Sequence[int], mcu_time_us: int, steering_rad: float = 0.0) -> Pose:
        """Add one sample: `counts` are each wheel's cumulative count, unwrapped (a differential
        drive gives two, an Ackermann robot at least one: its rear axle's), `mcu_time_us` the
        unwrapped MCU time of the sample, `steering_rad` the Ackermann angle held since the
        previous sample."""
        if not isinstance(counts, (tuple, list)) or len(counts) < self._wheels:
            raise ArgumentTypeError("counts", counts, f"a tuple of {self._wheels} or more integer counts")
        for k in range(self._wheels):
            checks.integer(f"counts[{k}]", counts[k], -(1 << 62), 1 << 62, what="an unwrapped count")
        checks.integer("mcu_time_us", mcu_time_us, 0, 1 << 62, what="an unwrapped MCU time in us")
        checks.number("steering_rad", steering_rad, -math.pi / 2, math.pi / 2, unit="rad", lo_open=True, hi_open=True)
        self.advance(counts, mcu_time_us, steering_rad)
        return self.pose

    def advance(self, counts: Sequence[int], mcu_time_us: int, steering_rad: float, host_time_s: float = 0.0) -> None:
        """`update` without the argument checks and without building a Pose: the session's
        per-frame path, fed values it has decoded and unwrapped itself, and the sample's host time
        (the pose's `time_s`)."""
        last, last_us = self._counts, self._time_us
        self._counts, self._time_us, self._host_s = counts, mcu_time_us, host_time_s
        if last is None or last_us is None:
            return
        kin = self.kinematics
        if isinstance(kin, DiffDrive):
            ds, dth = kin.motion(counts[0] - last[0], counts[1] - last[1])
        else:
            ds, dth = kin.motion(counts[0] - last[0], steering_rad)
        if ds or dth:
            self._x, self._y, self._theta = _integrate(self._x, self._y, self._theta, ds, dth)
        dt_us = mcu_time_us - last_us
        if dt_us > 0:
            self._v, self._w = ds * 1e6 / dt_us, dth * 1e6 / dt_us

    @property
    def pose(self) -> Pose:
        return Pose(
            self._x,
            self._y,
            self._theta,
            self._v,
            self._w,
            self._time_us or 0,
            self._gaps,
            self._position_unc,
            self._heading_unc,
            self._host_s,
        )
