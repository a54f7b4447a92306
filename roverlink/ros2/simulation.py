"""The emulator's extras on the graph, when the node runs against `emu://` (nothing of this exists
on a real board):

- `~/emulator/ground_truth` (nav_msgs/Odometry, 20 Hz): where the emulated robot really is, in
  the odom frame (the plant's pose relative to where it stood when odometry started), stamped when read;
  compare it with `odom` to see the odometry's error, as Gazebo's ground-truth plugin allows.
- `~/emulator/reset_board` (std_srvs/Trigger): pull the MCU's reset pin.
- `~/emulator/cut_link` (std_srvs/SetBool): cut (true) or restore (false) the serial cable.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.qos import QoSProfile
from std_srvs.srv import SetBool, Trigger

from host_sdk import Pose, Robot
from host_sdk.supervisor.connection import Connection
from roverlink.ros2 import convert

TRUTH_RATE_HZ = 20.0


class EmulatorInterface:
    def __init__(self, node: Node, connection: Connection, robot: Robot, odom_frame: str, base_frame: str) -> None:
        self._node = node
        self._connection = connection
        self._frames = odom_frame, base_frame
        self._origin = self._plant(robot.transport)
        """The plant's pose when the robot connected: where odometry starts."""
        self._pub = node.create_publisher(Odometry, "~/emulator/ground_truth", QoSProfile(depth=10))
        node.create_timer(1.0 / TRUTH_RATE_HZ, self._publish)
        node.create_service(Trigger, "~/emulator/reset_board", self._on_reset)
        node.create_service(SetBool, "~/emulator/cut_link", self._on_cut)

    def _emulator(self) -> Any:
        robot = self._connection.robot
        return None if robot is None else robot.transport

    @staticmethod
    def _plant(transport: Any) -> tuple[float, float, float] | None:
        if transport is None:
            return None
        with transport.locked() as emu:
            p = emu.truth.plant
            return p.x_m, p.y_m, p.theta_rad

    def truth_pose(self) -> Pose | None:
        """The plant's pose in the frame where odometry started."""
        raw, origin = self._plant(self._emulator()), self._origin
        if raw is None or origin is None:
            return None
        dx, dy = raw[0] - origin[0], raw[1] - origin[1]
        c, s = math.cos(-origin[2]), math.sin(-origin[2])
        return Pose(c * dx - s * dy, s * dx + c * dy, raw[2] - origin[2], 0.0, 0.0, 0)

    def _publish(self) -> None:
        pose = self.truth_pose()
        if pose is None:
            return
        msg = Odometry()
        convert.fill_odometry(
            msg,
            ns=self._node.get_clock().now().nanoseconds,
            odom_frame=self._frames[0],
            base_frame=self._frames[1],
            pose=pose,
            twist=(0.0, 0.0),
            pose_covariance=[0.0] * 36,
            twist_covariance=[0.0] * 36,
        )
        self._pub.publish(msg)

    def _fault(self, response: Any, act: Callable[[Any], str]) -> Any:
        transport = self._emulator()
        if transport is None:
            response.success, response.message = False, "no connection"
            return response
        with transport.locked() as emu:
            response.message = act(emu)
        response.success = True
        return response

    def _on_reset(self, request: Any, response: Any) -> Any:
        def reset(emu: Any) -> str:
            emu.reset_mcu()
            return "MCU reset"

        return self._fault(response, reset)

    def _on_cut(self, request: Any, response: Any) -> Any:
        def cut(emu: Any) -> str:
            if request.data:
                emu.cut_link()
                return "cut"
            emu.restore_link()
            return "restored"

        return self._fault(response, cut)
