"""The turn signals on the graph (a robot with the TURN_SIGNALS capability; docs/ros2.md, Lights):

- `~/lights` (std_msgs/String, subscribed): `auto`, `off`, or `manual steady=LAMPS slow=LAMPS
  fast=LAMPS` (host_sdk.lights.parse); sent to the board with SET_LIGHTS.
- `~/lights/state` (std_msgs/String, latched): the board's answer to GET_LIGHTS after each change,
  at each connection and after a board reset (which brings back the robot file's power-up mode).
- `~/get_lights` (std_srvs/Trigger): GET_LIGHTS now; the message is the state in the same words.
"""

from __future__ import annotations

from typing import Any

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String
from std_srvs.srv import Trigger

from host_sdk import Robot, RoverLinkError, lights
from host_sdk.supervisor.connection import Connection
from protocol.generated.enums import Capability

STATE_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
"""Latched: a node that subscribes later still gets the last state."""
REFRESH_S = 0.5
"""How often a state owed (after a reset or a failed read) is tried again."""


class LightsInterface:
    def __init__(self, node: Node, connection: Connection) -> None:
        self._node = node
        self._connection = connection
        self._owed = False
        """A state to publish: the board's lights changed without a command (a reset, a new session)."""
        self._pub = node.create_publisher(String, "~/lights/state", STATE_QOS)
        node.create_subscription(String, "~/lights", self._on_command, 10)
        node.create_service(Trigger, "~/get_lights", self._on_get)
        node.create_timer(REFRESH_S, self._refresh)

    def connected(self, robot: Robot) -> None:
        """A new connection (or session): its lights are the power-up mode; published when read."""
        self._owed = _has_lights(robot)
        robot.on_reset(lambda _error: self._owe())

    def _owe(self) -> None:
        self._owed = True

    def _refresh(self) -> None:
        robot = self._connection.robot
        if not self._owed or robot is None:
            return
        try:
            self._publish(robot.lights())
        except RoverLinkError:
            return  # the session is not back yet: the next period tries again
        self._owed = False

    def _publish(self, state: lights.LightsStatus) -> None:
        msg = String()
        msg.data = state.describe()
        self._pub.publish(msg)

    def _on_command(self, msg: Any) -> None:
        log = self._node.get_logger()
        robot = self._connection.robot
        if robot is None:
            log.warning(f"~/lights {msg.data!r} ignored: not connected to the robot")
            return
        try:
            state = robot.set_lights(**_arguments(lights.parse(msg.data)))
        except RoverLinkError as exc:
            log.warning(f"~/lights {msg.data!r} refused: {exc}")
            return
        self._publish(state)
        log.info(f"lights: {state.describe()}")

    def _on_get(self, request: Any, response: Any) -> Any:
        robot = self._connection.robot
        if robot is None:
            response.success, response.message = False, "not connected to the robot"
            return response
        try:
            state = robot.lights()
        except RoverLinkError as exc:
            response.success, response.message = False, str(exc)
            return response
        response.success, response.message = True, state.describe()
        return response


def _has_lights(robot: Robot) -> bool:
    return bool(robot.identity.capabilities & Capability.TURN_SIGNALS)


def _arguments(request: Any) -> dict[str, Any]:
    """Robot.set_lights's arguments for a parsed SET_LIGHTS."""
    args: dict[str, Any] = {"mode": request.mode}
    if request.mode.name == "MANUAL":
        args |= {"steady": request.steady, "slow": request.slow, "fast": request.fast}
    return args
