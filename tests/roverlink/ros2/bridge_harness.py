"""Test-side ROS 2 helpers: the bridge as a real `roverlink ros2` process, and a probe node that
talks to it over DDS (publishes cmd_vel, records what the bridge publishes, calls its services).

Waiting is always for a condition with a deadline, never a sleep.
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import subprocess
import sys
import threading
import time
import uuid
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import rclpy
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from sensor_msgs.msg import JointState
from std_srvs.srv import SetBool, Trigger

from tests.support.wait import wait_until

ROOT = Path(__file__).resolve().parents[3]


def yaw(q: Any) -> float:
    return 2 * math.atan2(q.z, q.w)


def stamp_s(stamp: Any) -> float:
    return float(stamp.sec) + stamp.nanosec * 1e-9


@dataclass
class Received:
    at: float
    """time.monotonic() when the probe got it."""
    ros_s: float
    """ROS time when the probe got it."""
    msg: Any


class BridgeProcess:
    """`python -m roverlink ros2 ...` in its own namespace, logging to a file."""

    def __init__(
        self,
        namespace: str,
        url: str,
        log_dir: Path,
        *,
        params: dict[str, Any] | None = None,
        extra: Sequence[str] = (),
        profile: str | None = None,
        robot_file: Path | None = None,
    ) -> None:
        self.namespace = namespace
        self.log_path = log_dir / f"{namespace.strip('/').replace('/', '_')}.log"
        args = [sys.executable, "-m", "roverlink", "ros2", "--url", url]
        args += ["--profile", profile] if profile else []
        args += ["--robot", str(robot_file)] if robot_file else []
        args += ["--ros-args"]
        args += [
            "-r",
            f"__ns:={namespace}",
            "-r",
            f"/tf:={namespace}/tf",
            "-r",
            f"/tf_static:={namespace}/tf_static",
            "-r",
            f"/diagnostics:={namespace}/diagnostics",
        ]
        for key, value in (params or {}).items():
            args += ["-p", f"{key}:={value}"]
        args += list(extra)
        self._log = self.log_path.open("w")
        self.proc = subprocess.Popen(args, stdout=self._log, stderr=subprocess.STDOUT, cwd=ROOT, env=os.environ.copy())

    def log(self) -> str:
        return self.log_path.read_text()

    def stop(self, sig: int = signal.SIGINT, timeout_s: float = 10.0) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
            try:
                self.proc.wait(timeout_s)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self._log.close()
        return self.proc.returncode


class Probe:
    """A node in the test process, in the bridge's namespace, spun on its own thread."""

    def __init__(self, namespace: str) -> None:
        self.node = Node(f"probe_{uuid.uuid4().hex[:8]}", namespace=namespace)
        self._lock = threading.Lock()
        self.received: dict[str, list[Received]] = {}
        self._sub("odom", Odometry, "odom")
        self._sub("joint_states", JointState, "joint_states")
        self._sub("diagnostics", DiagnosticArray, "diagnostics")
        self._sub("truth", Odometry, "roverlink/emulator/ground_truth")
        self.cmd_vel = self.node.create_publisher(Twist, "cmd_vel", 10)
        self.clients = {
            "arm": self.node.create_client(Trigger, "roverlink/arm"),
            "disarm": self.node.create_client(Trigger, "roverlink/disarm"),
            "reset_odometry": self.node.create_client(Trigger, "roverlink/reset_odometry"),
            "reset_board": self.node.create_client(Trigger, "roverlink/emulator/reset_board"),
            "cut_link": self.node.create_client(SetBool, "roverlink/emulator/cut_link"),
        }
        self._executor = SingleThreadedExecutor()
        self._executor.add_node(self.node)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def subscribe(self, key: str, msg_type: Any, topic: str, qos: Any = 10) -> None:
        self._sub(key, msg_type, topic, qos)

    def _sub(self, key: str, msg_type: Any, topic: str, qos: Any = 10) -> None:
        self.received[key] = []

        def record(msg: Any) -> None:
            ros_s = self.node.get_clock().now().nanoseconds * 1e-9
            with self._lock:
                self.received[key].append(Received(time.monotonic(), ros_s, msg))

        self.node.create_subscription(msg_type, topic, record, qos)

    def _spin(self) -> None:
        while not self._stop.is_set():
            self._executor.spin_once(timeout_sec=0.05)

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5)
        self._executor.shutdown()
        self.node.destroy_node()

    # -- reading ---------------------------------------------------------------------------------
    def since(self, key: str, t: float = 0.0) -> list[Received]:
        with self._lock:
            return [r for r in self.received[key] if r.at >= t]

    def last(self, key: str) -> Any:
        with self._lock:
            items = self.received[key]
            return items[-1].msg if items else None

    def wait_for(self, what: str, predicate: Callable[[], Any], timeout_s: float = 10.0) -> Any:
        return wait_until(predicate, timeout_s, what)

    def wait_message(self, key: str, after: float = 0.0, timeout_s: float = 10.0) -> Any:
        return self.wait_for(f"a message on {key}", lambda: (self.since(key, after) or [None])[-1], timeout_s).msg

    def status(self, part: str, after: float = 0.0) -> Any:
        """The latest diagnostics status whose name ends with `part` ("link" or "robot")."""
        for r in reversed(self.since("diagnostics", after)):
            for status in r.msg.status:
                if status.name.endswith(f": {part}"):
                    return status
        return None

    def wait_status(self, part: str, predicate: Callable[[Any], bool], timeout_s: float = 10.0) -> Any:
        def check() -> Any:
            for r in reversed(self.since("diagnostics")):
                for status in r.msg.status:
                    if status.name.endswith(f": {part}") and predicate(status):
                        return status
                break  # only the newest report counts
            return None

        return self.wait_for(f"a {part} status that fits", check, timeout_s)

    # -- acting ----------------------------------------------------------------------------------
    def call(self, service: str, request: Any = None, timeout_s: float = 10.0) -> Any:
        client = self.clients[service]
        if not client.wait_for_service(timeout_sec=timeout_s):
            raise AssertionError(f"service {service} is not available")
        if request is None:
            request = Trigger.Request()
        future = client.call_async(request)
        self.wait_for(f"the answer of {service}", future.done, timeout_s)
        return future.result()

    def twist(self, linear: float, angular: float) -> None:
        msg = Twist()
        msg.linear.x, msg.angular.z = float(linear), float(angular)
        self.cmd_vel.publish(msg)

    def drive(self, linear: float, angular: float, seconds: float, rate_hz: float = 20.0) -> float:
        """Publish a twist at `rate_hz` for `seconds`; returns the monotonic time of the last one."""
        end = time.monotonic() + seconds
        last = time.monotonic()
        while time.monotonic() < end:
            self.twist(linear, angular)
            last = time.monotonic()
            time.sleep(1.0 / rate_hz)  # pacing a publisher, not synchronising
        return last


@contextlib.contextmanager
def logged(proc: BridgeProcess, probe: Probe) -> Iterator[None]:
    """Print the bridge's log if the body fails; close the probe and stop the bridge after it."""
    try:
        yield
    except BaseException:
        print(proc.log())
        raise
    finally:
        probe.close()
        proc.stop()


def values(status: Any) -> dict[str, str]:
    return {kv.key: kv.value for kv in status.values}


def init_ros() -> None:
    if not rclpy.ok():
        rclpy.init()
