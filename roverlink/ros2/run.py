"""Run the bridge node until SIGINT or SIGTERM, then stop, disarm and close the robot."""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Sequence
from types import FrameType
from typing import Any

import rclpy
from rclpy.exceptions import NameValidationException, ParameterException
from rclpy.executors import SingleThreadedExecutor
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import try_shutdown

from host_sdk import RoverLinkError
from host_sdk.hostinfo import realtime
from roverlink import say
from roverlink.ros2.node import BridgeNode

SWITCH_INTERVAL_S = 0.001
"""How long a thread holding the GIL keeps it while another asks for it (Python's default: 5 ms).
The SDK's I/O thread wakes for each FEEDBACK and each lockstep slot and must get the GIL from the
lidar's, the IMU's and the executor's threads within a few ms of a board tick; 5 ms per wake-up
made it miss ticks on a loaded host."""


def run(ros_args: Sequence[str], overrides: dict[str, Any]) -> int:
    """`ros_args`: what follows --ros-args; `overrides`: parameters set on the command line (they win
    over a parameters file). Returns the exit status: 0 after a signal, 1 when connecting cannot
    succeed (e.g. incompatible firmware) or a parameter is wrong."""
    stop = threading.Event()
    sys.setswitchinterval(SWITCH_INTERVAL_S)  # this process is the node's own: its policy is ours

    def on_signal(signum: int, frame: FrameType | None) -> None:
        stop.set()

    # The node handles the signals itself, so shutdown is ordered: robot first, then ROS.
    rclpy.init(args=["roverlink", "--ros-args", *ros_args], signal_handler_options=SignalHandlerOptions.NO)
    previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
    node: BridgeNode | None = None
    status = 0
    try:
        node = BridgeNode(overrides)
        if node.params.realtime_priority:  # after the node's threads exist; later ones inherit it
            threads = realtime.make_realtime(node.params.realtime_priority)
            node.get_logger().info(
                f"realtime_priority: {threads} threads under SCHED_FIFO {node.params.realtime_priority}"
            )
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.1)
            if node.connection.fatal is not None:  # logged to the ROS log; the command says it ended
                say.error(f"cannot connect: {node.connection.fatal}")
                status = 1
                break
    except (RoverLinkError, ParameterException, NameValidationException) as exc:
        # A parameter out of its range or of the wrong type, a bad namespace or node name.
        say.error(exc)
        status = 1
    finally:
        if node is not None:
            node.close()
            node.destroy_node()
        try_shutdown()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return status
