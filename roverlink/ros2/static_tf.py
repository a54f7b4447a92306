"""The node's `/tf_static`: base_link -> base_footprint and -> each sensor's frame at its mount.

The transforms are roverlink.ros2.frames' (the same the URDF of `roverlink robot urdf` has): the
robot file's mounts when the node has one; else the reference robot's mounts of the devices the
node runs (lidar, IMU). Published with tf2_ros StaticTransformBroadcaster's QoS (depth 1,
reliable, transient local: a late subscriber still gets them), each message the full set: once
when the node starts, and again only if the set changes (an emulated robot's devices become known
when it connects). `publish_static_tf:=false` when robot_state_publisher publishes the URDF.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from host_sdk import Robot
from host_sdk.geometry import description_of, profile_of
from protocol.generated.profiles import ROBOT_SENSORS
from protocol.robotfile import RobotFile
from roverlink.ros2 import convert
from roverlink.ros2.frames import FrameNames, StaticFrame, static_frames
from roverlink.ros2.params import BridgeParams

STATIC_QOS = QoSProfile(
    depth=1,
    history=HistoryPolicy.KEEP_LAST,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)
"""What tf2_ros's StaticTransformBroadcaster uses."""


def frame_names(params: BridgeParams) -> FrameNames:
    return FrameNames(
        base=params.base_frame,
        lidar=params.lidar_frame,
        imu=params.imu_frame,
        wheel_joints=params.wheel_joints,
        steering_joint=params.steering_joint,
    )


def fill_static(msg: Any, frame: StaticFrame, ns: int) -> None:
    """geometry_msgs/TransformStamped of one fixed frame."""
    convert.set_stamp(msg.header.stamp, ns)
    msg.header.frame_id, msg.child_frame_id = frame.parent, frame.child
    t = msg.transform
    t.translation.x, t.translation.y, t.translation.z = frame.x, frame.y, frame.z
    q = convert.euler_quaternion(frame.roll, frame.pitch, frame.yaw)
    t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w = q


class StaticTf:
    def __init__(self, node: Node, tf_type: Any, params: BridgeParams, robot_file: RobotFile | None) -> None:
        self._node = node
        self._type = tf_type
        self._names = frame_names(params)
        self._robot_file = robot_file
        self._profile = params.profile or None
        self._sent: tuple[StaticFrame, ...] | None = None
        self._pub = node.create_publisher(tf_type, "/tf_static", STATIC_QOS)

    def _source(self, robot: Robot | None, fallback: str | None) -> RobotFile | str | None:
        """The robot file, the profile parameter, the connected robot's file or reference robot,
        else the emu:// URL's profile."""
        if self._robot_file is not None or self._profile is not None:
            return self._robot_file or self._profile
        if robot is not None:
            desc = description_of(robot)
            if desc is not None:
                return desc
            fallback = profile_of(robot) or fallback
        return fallback if fallback in ROBOT_SENSORS else None

    def update(self, robot: Robot | None, profile: str | None, kinds: Iterable[str]) -> None:
        """Publish the frames (if they differ from the last sent) for the devices of `kinds`."""
        source = self._source(robot, profile)
        if source is None:
            return  # no robot known yet: nothing to place the sensors with
        frames = static_frames(source, self._names, None if isinstance(source, RobotFile) else kinds)
        if frames == self._sent:
            return
        ns = self._node.get_clock().now().nanoseconds
        msg = self._type()
        for frame in frames:
            transform = TransformStamped()
            fill_static(transform, frame, ns)
            msg.transforms.append(transform)
        self._pub.publish(msg)
        self._sent = frames
        self._node.get_logger().info("static frames on /tf_static: " + ", ".join(f.child for f in frames))
