"""The node's fused odometry and the services that set its pose.

- `odometry/filtered` (nav_msgs/Odometry, odom_frame -> base_frame, as robot_localization names
  it), with an IMU: wheel odometry + the IMU's gyro in the SDK's EKF (roverlink.ros2.fusion), one
  message per FEEDBACK; the pose covariance is the EKF's (x, y, yaw). With `tf_from: fused` /tf's
  odom_frame -> base_frame is this pose (and the wheel odometry's transform is not published).
- `~/reset_odometry` (std_srvs/Trigger): the pose to (0, 0, 0) in wheel odometry and the EKF.
- `~/set_pose` (geometry_msgs/PoseWithCovarianceStamped, as robot_localization's `set_pose`): the
  pose to the message's x, y and yaw (z, roll, pitch and the covariance are not used).

Threads: FEEDBACK on the SDK's I/O thread, IMU samples on the IMU's thread, the pose services on
the executor's: one lock around the EKF, its queue, the wheel odometry's reset and the publishing
(so fused messages go out in time order).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence
from typing import Any

from geometry_msgs.msg import PoseWithCovarianceStamped, TransformStamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.qos import QoSProfile, qos_profile_sensor_data
from std_srvs.srv import Trigger

from host_sdk import FeedbackSample, Pose, RoverLinkError
from host_sdk.fusion import params_for
from host_sdk.sensors import ImuSample
from host_sdk.supervisor.connection import Connection
from roverlink.ros2 import convert
from roverlink.ros2.fusion import FusedOdometry, Fusion, PoseGate, check_tf_from, imu_expected, imu_time
from roverlink.ros2.params import BridgeParams
from roverlink.ros2.robotfacts import FILTERED_ODOM as FILTERED_TOPIC


def start(
    node: Node, connection: Connection, params: BridgeParams, emu_options: Any, tf: tuple[Any, Any]
) -> FusedPublisher | None:
    """odometry/filtered when the node will have an IMU (None without one); `tf`: /tf's publisher and
    message type, used with `tf_from: fused`. A `tf_from: fused` without an IMU is refused here."""
    has_imu = imu_expected(params, emu_options)
    check_tf_from(params, has_imu)
    return FusedPublisher(node, connection, params, tf) if has_imu else None


class FusedPublisher:
    """Feeds the EKF from the node's FEEDBACK and IMU threads and publishes odometry/filtered."""

    def __init__(self, node: Node, connection: Connection, params: BridgeParams, tf: tuple[Any, Any]) -> None:
        self._node = node
        self._connection = connection
        self._params = params
        self._tf_pub: Any = tf[0] if params.tf_from == "fused" else None
        self._tf_type: Any = tf[1]
        self.lock = threading.Lock()
        self.core: Fusion | None = None
        self.published = 0
        qos = QoSProfile(depth=params.qos_depth)  # as odom's (odom_qos)
        if params.odom_qos == "sensor_data":
            qos.reliability = qos_profile_sensor_data.reliability
        self._pub = node.create_publisher(Odometry, FILTERED_TOPIC, qos)
        gyro = params.imu_angular_velocity_covariance_diagonal
        self._gyro_variance = float(gyro[2])
        self._twist_covariance = convert.covariance(params.twist_covariance_diagonal)

    def _fusion(self, start_s: float) -> Fusion:
        if self.core is None:
            robot = self._connection.robot
            params = params_for(robot.kinematics if robot is not None else None)  # as PoseSource makes its own
            self.core = Fusion(start_s, gyro_variance=self._gyro_variance, params=params)
        return self.core

    # -- inputs (their threads) -------------------------------------------------------------------------
    def on_feedback(self, sample: FeedbackSample, twist: tuple[float, float]) -> None:
        pose = sample.pose
        if pose is None:
            return
        with self.lock:
            core = self._fusion(sample.host_time_s)
            steps = core.add_odometry(sample.host_time_s, (pose.x_m, pose.y_m, pose.theta_rad), *twist)
            self._publish(steps)

    def on_imu(self, sample: ImuSample, port_now: float) -> None:
        robot = self._connection.robot
        if robot is None or sample.gyro is None:
            return
        try:
            t = imu_time(sample.t, port_now, robot.now())
        except RoverLinkError:  # closed meanwhile
            return
        with self.lock:
            self._publish(self._fusion(t).add_gyro(t, sample.gyro[2]))

    def set_pose(self, robot: Any, x_m: float, y_m: float, theta_rad: float) -> None:
        """Wheel odometry and the EKF to (x, y, theta), together (no sample fused in between)."""
        with self.lock:
            robot.odometry.reset(x_m, y_m, theta_rad)
            core = self._fusion(robot.now())
            self._publish(core.set_pose(x_m, y_m, theta_rad))

    # -- output ---------------------------------------------------------------------------------------
    def _publish(self, steps: list[FusedOdometry]) -> None:
        robot = self._connection.robot
        if not steps or robot is None:
            return
        p = self._params
        try:
            robot_now = robot.now()
        except RoverLinkError:
            return
        ros_now = self._node.get_clock().now().nanoseconds
        for step in steps:
            ns = convert.stamp_ns(step.time_s, robot_now, ros_now)
            pose = Pose(step.x_m, step.y_m, step.theta_rad, step.linear_m_s, step.angular_rad_s, 0)
            twist_cov = list(self._twist_covariance)
            if step.angular_variance is not None:
                twist_cov[35] = step.angular_variance
            cov = convert.fused_pose_covariance(step.covariance, p.pose_covariance_diagonal)
            twist = (step.linear_m_s, step.angular_rad_s)
            publish_odometry(
                p, self._pub, (self._tf_pub, self._tf_type), ns=ns, pose=pose, twist=twist, covariances=(cov, twist_cov)
            )
            self.published += 1


def publish_odometry(
    params: BridgeParams,
    pub: Any,
    tf: tuple[Any, Any],
    *,
    ns: int,
    pose: Pose,
    twist: tuple[float, float],
    covariances: tuple[Sequence[float], Sequence[float]],
) -> None:
    """nav_msgs/Odometry on `pub` and, when `tf` is (a publisher, the TFMessage type), the same
    pose as odom_frame -> base_frame; `covariances`: (pose, twist), 6x6 row-major each."""
    msg = Odometry()
    frames = {"odom_frame": params.odom_frame, "base_frame": params.base_frame}
    convert.fill_odometry(
        msg, ns=ns, **frames, pose=pose, twist=twist, pose_covariance=covariances[0], twist_covariance=covariances[1]
    )
    pub.publish(msg)
    tf_pub, tf_type = tf
    if tf_pub is not None:
        transform = TransformStamped()
        convert.fill_transform(transform, ns=ns, **frames, pose=pose)
        tf_pub.publish(tf_type(transforms=[transform]))


def yaw_of(q: Any) -> float:
    """The yaw of a quaternion (x, y, z, w), about z."""
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


class PoseServices:
    """`~/reset_odometry` and `~/set_pose`: they work armed or not, driving or not."""

    def __init__(self, node: Node, connection: Connection, params: BridgeParams, fused: FusedPublisher | None) -> None:
        self._node = node
        self._connection = connection
        self._params = params
        self._fused = fused
        self._gate = PoseGate()
        node.create_service(Trigger, "~/reset_odometry", self._on_reset)
        node.create_subscription(PoseWithCovarianceStamped, "~/set_pose", self._on_set_pose, 10)

    def set_pose(self, x_m: float, y_m: float, theta_rad: float) -> str:
        """Set the pose; returns what was done (RoverLinkError: not connected, or a bad value)."""
        robot = self._connection.robot
        if robot is None:
            raise RoverLinkError(f"no connection to {self._params.url}: the pose was not set")
        was = robot.odometry.pose
        if self._fused is not None:
            self._fused.set_pose(robot, x_m, y_m, theta_rad)
        else:
            robot.odometry.reset(x_m, y_m, theta_rad)
        self._gate.expect(x_m, y_m, theta_rad)
        where = "wheel odometry and the EKF" if self._fused is not None else "wheel odometry"
        return (
            f"{where} set to x={x_m:.3f} m, y={y_m:.3f} m, yaw={math.degrees(theta_rad):.1f} deg "
            f"(was x={was.x_m:.3f} m, y={was.y_m:.3f} m, yaw={math.degrees(was.theta_rad):.1f} deg); "
            "joint angles unchanged"
        )

    def accept(self, sample: FeedbackSample) -> bool:
        """False for a FEEDBACK integrated before the pose was last set (its odom would jump back)."""
        pose = sample.pose
        return pose is None or self._gate.accept((pose.x_m, pose.y_m, pose.theta_rad))

    def _on_reset(self, request: Any, response: Any) -> Any:
        try:
            response.message = self.set_pose(0.0, 0.0, 0.0)
        except RoverLinkError as exc:
            response.success, response.message = False, str(exc)
            self._node.get_logger().warning(f"~/reset_odometry: {exc}")
            return response
        response.success = True
        self._node.get_logger().info(f"~/reset_odometry: {response.message}")
        return response

    def _on_set_pose(self, msg: Any) -> None:
        log = self._node.get_logger()
        frame = msg.header.frame_id
        if frame not in ("", self._params.odom_frame):
            log.warning(f"~/set_pose ignored: its frame is {frame!r}, not {self._params.odom_frame!r} (odom_frame)")
            return
        pose = msg.pose.pose
        try:
            text = self.set_pose(float(pose.position.x), float(pose.position.y), yaw_of(pose.orientation))
        except RoverLinkError as exc:
            log.warning(f"~/set_pose: {exc}")
            return
        log.info(f"~/set_pose: {text} (x, y and yaw used; z, roll, pitch and the covariance are not)")
