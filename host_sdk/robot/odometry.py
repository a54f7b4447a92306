"""`robot.odometry`: the pose and body velocity the session integrates, read and reset from any
thread (under the robot's lock)."""

from __future__ import annotations

import math

from host_sdk import checks
from host_sdk.errors import RoverLinkError, UnsupportedError
from host_sdk.odometry import MAX_POSITION_M
from host_sdk.pose import Pose
from host_sdk.robot.link import Link

_POSE = ("x_m", "y_m", "theta_rad")


class OdometryView:
    """The robot's odometry: pose and body velocity from cumulative encoder counts (thread-safe view)."""

    def __init__(self, link: Link) -> None:
        self._link = link

    @property
    def pose(self) -> Pose:
        """x, y (m), theta (rad, unwrapped), linear and angular velocity, MCU time of the last sample."""
        with self._link.lock:
            self._link.check_open()
            pose = self._link.session.pose()
        if pose is None:
            raise self._unsupported()
        return pose

    def reset(self, x_m: float = 0.0, y_m: float = 0.0, theta_rad: float = 0.0) -> None:
        """Set the pose (default: the origin); counting goes on from the next sample."""
        pose = zip(_POSE, (x_m, y_m, theta_rad), strict=True)
        values = [checks.number(n, v, -MAX_POSITION_M, MAX_POSITION_M) for n, v in pose]
        with self._link.lock:
            self._link.check_open()
            if not self._link.session.reset_pose(*values):
                raise self._unsupported()

    @staticmethod
    def _unsupported() -> UnsupportedError:
        return UnsupportedError(
            "odometry needs the robot's kinematics: pass profile=... or kinematics=... to Robot.connect"
        )

    def __repr__(self) -> str:
        try:
            p = self.pose
        except RoverLinkError:
            return "<Odometry unavailable>"
        return f"<Odometry x={p.x_m:.3f} m y={p.y_m:.3f} m theta={math.degrees(p.theta_rad):.1f} deg>"
