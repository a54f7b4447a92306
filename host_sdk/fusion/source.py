"""The robot's pose now and at recent times, for a robot program: the EKF's (wheel odometry + the
IMU's gyro) when an IMU is given, else wheel odometry; with the speeds the board measured.

    poses = PoseSource(robot, imu)        # imu: a host_sdk.sensors.Jy901, or None
    pose = poses.update(robot.now())      # Pose: time, x, y, theta, measured speeds
    then = poses.at(scan_time)            # interpolated between the recent poses
"""

from __future__ import annotations

import bisect
import math
from collections import deque

from host_sdk.fusion.ekf import OdometryIncrements, PoseEkf
from host_sdk.fusion.ekf_params import params_for
from host_sdk.pose import Pose, interpolate
from host_sdk.robot import Robot
from host_sdk.sensors.imu import Jy901
from host_sdk.session import FeedbackSample

HISTORY = 64
"""Poses kept for `at()`: 3.2 s at a 20 Hz control loop, longer than a lidar revolution's skew."""


class PoseSource:
    """Call `update(t)` once per control period, from the loop's thread."""

    def __init__(self, robot: Robot, imu: Jy901 | None) -> None:
        self.robot = robot
        self.imu = imu
        self.ekf: PoseEkf | None = None
        self._history: deque[Pose] = deque(maxlen=HISTORY)
        self.distance_m = 0.0
        """Distance driven (odometry), m."""
        self._steps = OdometryIncrements()
        self._odometry: deque[tuple[float, float, float]] = deque()
        """(time, distance, turn) steps from FEEDBACK, not yet fused."""
        if imu is not None:
            self.ekf = PoseEkf(params_for(robot.kinematics), time_s=robot.now())
            robot.on_feedback(self._on_feedback)

    def use(self, robot: Robot) -> None:
        """Go on with `robot`: the same robot connected again after its port was lost (its odometry
        carries the pose on, host_sdk.supervisor)."""
        self.robot = robot
        if self.imu is not None:
            robot.on_feedback(self._on_feedback)

    def _on_feedback(self, sample: FeedbackSample) -> None:
        # On the I/O thread: queued, and fused on the loop's thread once the IMU has been read up to
        # now (a step fused before its gyro samples are in would have to guess the turn).
        if sample.pose is not None:
            ds, turn = self._steps.step(sample.pose.x_m, sample.pose.y_m, sample.pose.theta_rad)
            self._odometry.append((sample.host_time_s, ds, turn))

    def update(self, t: float) -> Pose:
        """The pose at `t` (now), kept for `at()`."""
        wheels = self.robot.odometry.pose
        if self.imu is not None and self.ekf is not None:
            for sample in self.imu.poll():
                if sample.gyro is not None:
                    self.ekf.add_gyro(sample.t, sample.gyro[2])
            while self._odometry:
                time_s, ds, turn = self._odometry.popleft()
                self.ekf.add_odometry(time_s, ds, turn)
                self.distance_m += abs(ds)
            p = self.ekf.pose
            x, y, theta = p.x_m, p.y_m, p.theta_rad
        else:
            x, y, theta = wheels.x_m, wheels.y_m, wheels.theta_rad
            if self._history:
                last = self._history[-1]
                self.distance_m += math.hypot(x - last.x_m, y - last.y_m)
        pose = Pose(x, y, theta, wheels.linear_m_s, wheels.angular_rad_s, time_s=t)
        self._history.append(pose)
        return pose

    def at(self, t: float) -> Pose:
        """The pose at `t`, interpolated between the recent ones (held beyond them). A control step
        is 50 ms: the nearest pose alone would be up to 2.5 cm and 2 degrees off while turning, which
        is what a lidar revolution is registered and compared by."""
        history = self._history
        i = bisect.bisect_left(history, t, key=lambda p: p.time_s)
        if i <= 0:
            return history[0]
        if i >= len(history):
            return history[-1]
        a, b = history[i - 1], history[i]
        f = (t - a.time_s) / (b.time_s - a.time_s) if b.time_s > a.time_s else 1.0
        return a.moved_to(t, interpolate(a.xyt, b.xyt, f))
