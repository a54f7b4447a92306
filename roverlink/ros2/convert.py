"""Robot and sensor state -> ROS message contents (REP-103 units and axes: m, rad, x forward, z up).

The arithmetic is plain functions on SDK values; the `fill_*` functions copy results into rclpy
message objects, which they take duck-typed, so all of this is testable without ROS.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from host_sdk import Ackermann, DiffDrive, FeedbackSample, Pose
from host_sdk.sensors import ImuSample, RegularScan

_NS = 1_000_000_000


def yaw_quaternion(theta_rad: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation by `theta_rad` about z."""
    half = theta_rad / 2
    return 0.0, 0.0, math.sin(half), math.cos(half)


def body_twist(kinematics: DiffDrive | Ackermann, sample: FeedbackSample) -> tuple[float, float]:
    """(linear m/s, angular rad/s) of the body from the wheel speeds the board measured."""
    speeds = sample.wheel_speeds_m_s
    if isinstance(kinematics, DiffDrive):
        return kinematics.twist(speeds[0], speeds[1])
    v = speeds[0]
    return v, v * math.tan(sample.steering_rad) / kinematics.wheelbase_m


def stamp_ns(sample_host_s: float, host_now_s: float, ros_now_ns: int) -> int:
    """ROS time of a sample: ROS now less the sample's age on the host clock.

    `sample_host_s` is the MCU tick time mapped to the host clock by the SDK's time sync, so the
    stamp is when the board sampled, not when the frame was read."""
    return ros_now_ns - round((host_now_s - sample_host_s) * 1e9)


def covariance(diagonal: Sequence[float]) -> list[float]:
    """A row-major 6x6 covariance with `diagonal` on its diagonal."""
    out = [0.0] * 36
    for i, value in enumerate(diagonal):
        out[i * 7] = float(value)
    return out


def pose_covariance(diagonal: Sequence[float], pose: Pose) -> list[float]:
    """The odom pose covariance: the configured `diagonal`, with the variance of what encoder
    counts lost to board resets may have cost (the pose's uncertainty, taken as one standard
    deviation) added to x, y and yaw."""
    position, heading = pose.position_uncertainty_m**2, pose.heading_uncertainty_rad**2
    grown = [float(v) for v in diagonal]
    grown[0] += position
    grown[1] += position
    grown[5] += heading
    return covariance(grown)


def default_wheel_joints(kinematics: DiffDrive | Ackermann) -> tuple[str, ...]:
    if isinstance(kinematics, DiffDrive):
        return ("left_wheel_joint", "right_wheel_joint")
    return ("rear_wheel_joint",)


@dataclass(frozen=True, slots=True)
class JointSample:
    names: tuple[str, ...]
    positions: tuple[float, ...]
    velocities: tuple[float, ...]


class JointTracker:
    """Wheel angles from cumulative encoder counts, continuous across board resets.

    A reset restarts the board's counts; the angle carries on from where it was (what the wheels
    turned while the board was down is lost, as it is for odometry)."""

    def __init__(self, kinematics: DiffDrive | Ackermann, wheel_names: Sequence[str], steering_name: str) -> None:
        wheels = 2 if isinstance(kinematics, DiffDrive) else 1
        if len(wheel_names) != wheels:
            raise ValueError(f"wheel_joints has {len(wheel_names)} names; this robot has {wheels} encoded wheels")
        self.kinematics = kinematics
        self.names = (*wheel_names, *([steering_name] if isinstance(kinematics, Ackermann) else []))
        self._rad_per_count = 2 * math.pi / kinematics.counts_per_rev
        self._offset = [0] * wheels
        self._last: tuple[int, ...] | None = None
        self._boot_id: int | None = None
        self._steering: tuple[float, int] | None = None

    def update(self, sample: FeedbackSample) -> JointSample:
        counts = sample.encoder_counts[: len(self._offset)]
        if self._last is not None and sample.boot_id != self._boot_id:
            self._offset = [o + last - new for o, last, new in zip(self._offset, self._last, counts, strict=True)]
        self._last, self._boot_id = counts, sample.boot_id
        positions = [(o + c) * self._rad_per_count for o, c in zip(self._offset, counts, strict=True)]
        radius = self.kinematics.wheel_radius_m
        velocities = [s / radius for s in sample.wheel_speeds_m_s[: len(self._offset)]]
        if isinstance(self.kinematics, Ackermann):
            rate = 0.0
            if self._steering is not None and sample.mcu_time_us > self._steering[1]:
                rate = (sample.steering_rad - self._steering[0]) * 1e6 / (sample.mcu_time_us - self._steering[1])
            self._steering = (sample.steering_rad, sample.mcu_time_us)
            positions.append(sample.steering_rad)
            velocities.append(rate)
        return JointSample(self.names, tuple(positions), tuple(velocities))


def set_stamp(stamp: Any, ns: int) -> None:
    stamp.sec, stamp.nanosec = divmod(ns, _NS)


def fill_odometry(
    msg: Any,
    *,
    ns: int,
    odom_frame: str,
    base_frame: str,
    pose: Pose,
    twist: tuple[float, float],
    pose_covariance: Sequence[float],
    twist_covariance: Sequence[float],
) -> None:
    """nav_msgs/Odometry: the pose in `odom_frame`, the twist in `base_frame`."""
    set_stamp(msg.header.stamp, ns)
    msg.header.frame_id = odom_frame
    msg.child_frame_id = base_frame
    p = msg.pose.pose
    p.position.x, p.position.y, p.position.z = pose.x_m, pose.y_m, 0.0
    q = yaw_quaternion(pose.theta_rad)
    p.orientation.x, p.orientation.y, p.orientation.z, p.orientation.w = q
    msg.pose.covariance = pose_covariance
    t = msg.twist.twist
    t.linear.x, t.linear.y, t.linear.z = twist[0], 0.0, 0.0
    t.angular.x, t.angular.y, t.angular.z = 0.0, 0.0, twist[1]
    msg.twist.covariance = twist_covariance


def fill_transform(msg: Any, *, ns: int, odom_frame: str, base_frame: str, pose: Pose) -> None:
    """geometry_msgs/TransformStamped odom_frame -> base_frame."""
    set_stamp(msg.header.stamp, ns)
    msg.header.frame_id = odom_frame
    msg.child_frame_id = base_frame
    tr = msg.transform
    tr.translation.x, tr.translation.y, tr.translation.z = pose.x_m, pose.y_m, 0.0
    tr.rotation.x, tr.rotation.y, tr.rotation.z, tr.rotation.w = yaw_quaternion(pose.theta_rad)


def fill_joint_state(msg: Any, *, ns: int, joints: JointSample) -> None:
    set_stamp(msg.header.stamp, ns)
    msg.name = list(joints.names)
    msg.position = list(joints.positions)
    msg.velocity = list(joints.velocities)


def euler_quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of roll about x, then pitch about y, then yaw about z (fixed axes)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def fill_laser_scan(msg: Any, *, ns: int, frame: str, scan: RegularScan) -> None:
    """sensor_msgs/LaserScan from a binned scan; `ns` is ray 0's time (a LaserScanData, the node's,
    carries REP 117's -inf / +inf / NaN classes: host_sdk.sensors.laserscan)."""
    set_stamp(msg.header.stamp, ns)
    msg.header.frame_id = frame
    n = len(scan.ranges_m)
    msg.angle_min = scan.angle_min
    msg.angle_max = scan.angle_min + (n - 1) * scan.angle_increment
    msg.angle_increment = scan.angle_increment
    msg.time_increment = scan.time_increment_s
    msg.scan_time = scan.scan_time_s
    msg.range_min, msg.range_max = scan.range_min_m, scan.range_max_m
    msg.ranges = [float(r) for r in scan.ranges_m]
    msg.intensities = [float(i) for i in scan.intensities]


@dataclass(frozen=True, slots=True)
class ImuCovariance:
    """Diagonals (x, y, z) of the three covariances of sensor_msgs/Imu."""

    orientation: tuple[float, ...]
    angular_velocity: tuple[float, ...]
    linear_acceleration: tuple[float, ...]


def _diagonal3(values: Sequence[float]) -> list[float]:
    out = [0.0] * 9
    for i, value in enumerate(values):
        out[i * 4] = float(value)
    return out


def fill_imu(msg: Any, *, ns: int, frame: str, sample: ImuSample, covariance: ImuCovariance) -> None:
    """sensor_msgs/Imu from one JY901 output period, with `covariance`'s diagonals. What the module
    was not set to send gets covariance[0] = -1 (the message's "not provided")."""
    set_stamp(msg.header.stamp, ns)
    msg.header.frame_id = frame
    q: tuple[float, float, float, float] | None = None
    if sample.quaternion is not None:
        w, x, y, z = sample.quaternion
        q = (x, y, z, w)
    elif sample.angle is not None:
        q = euler_quaternion(*sample.angle)
    if q is None:
        msg.orientation_covariance = [-1.0] + [0.0] * 8
    else:
        o = msg.orientation
        o.x, o.y, o.z, o.w = q
        msg.orientation_covariance = _diagonal3(covariance.orientation)
    msg.angular_velocity_covariance = _fill_vector(msg.angular_velocity, sample.gyro, covariance.angular_velocity)
    msg.linear_acceleration_covariance = _fill_vector(
        msg.linear_acceleration, sample.accel, covariance.linear_acceleration
    )


def _fill_vector(vector: Any, value: tuple[float, float, float] | None, diagonal: Sequence[float]) -> list[float]:
    """geometry_msgs/Vector3 set to `value`; returns its covariance (-1 first: not provided)."""
    if value is None:
        return [-1.0] + [0.0] * 8
    vector.x, vector.y, vector.z = value
    return _diagonal3(diagonal)


def fused_pose_covariance(pose_3x3: Sequence[float], diagonal: Sequence[float]) -> list[float]:
    """The 6x6 pose covariance of odometry/filtered: x, y and yaw (with their cross terms) from the
    EKF's 3x3 covariance of (x, y, theta), z, roll and pitch from `diagonal` (the 2D robot's)."""
    out = covariance(diagonal)
    axes = (0, 1, 5)  # x, y, yaw in the 6x6 (x, y, z, roll, pitch, yaw)
    for i, row in enumerate(axes):
        for j, col in enumerate(axes):
            out[row * 6 + col] = float(pose_3x3[i * 3 + j])
    return out
