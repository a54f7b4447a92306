"""ROS 2 bridge benchmark: cmd_vel-to-applied latency, odometry rate and stamp jitter, and the
bridge's CPU against a minimal rclpy node, measured in one run on one machine.

What is measured
----------------
1. **cmd_vel -> applied latency** (stream and lockstep mode). The bridge runs in this process
   against the in-process emulator (`emu://diffdrive-tb6612`, real clock) with a tap on its
   transport that decodes every frame written and read. A second node publishes Twists with a
   distinct speed each at 20 Hz. For each one: from `publish()` to the arrival of the first
   FEEDBACK whose `ack_seq` shows that the setpoint carrying that speed (the first frame sent
   with it) was applied by the firmware. This is DDS delivery + the node's callback + the SDK +
   the serial line + the firmware's next control tick + the FEEDBACK that reports it.
2. **odom rate and stamp jitter**. The real deployment shape: `roverlink emulate` serves the
   emulated board on a pseudo-terminal in its own process, and `roverlink ros2 --url /dev/pts/N`
   runs as its own process at odom_rate 50. The benchmark subscribes to `odom` and reports the
   rate and, for consecutive messages, how far the header stamp interval and the arrival interval
   are from the nominal 20 ms. The stamps come from the MCU's clock (through the SDK's time sync),
   the arrival times from this host's scheduler.
3. **CPU at 50 Hz odom**. Over the same window, CPU time (user + system, /proc) of the bridge
   process and of a minimal rclpy node (this file with --relay) that only subscribes to Twist and
   publishes Odometry at 50 Hz, both fed the same 20 Hz cmd_vel. The ratio is the cost of
   everything the bridge does beyond relaying: the serial link, session, time sync, odometry,
   joint_states, /tf, diagnostics.

Run: python benchmarks/ros2.py [--seconds 15] [--commands 150] [--json out.json]
     python benchmarks/ros2.py --loaded [--seconds 600] [--hogs 2] [--warn-only] [--realtime-priority N]: the node on a
     loaded host (ros2_loaded.py); exit status 1 when it misses a goal (with --warn-only: only
     when the run is invalid).
Needs the `ros2` extra (rclpy, message packages); /tf is published if tf2_msgs is importable or
built into build/ros2 (python -m roverlink.ros2.interfaces --prefix build/ros2).
"""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import itertools
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import rclpy
import ros2_loaded  # beside this file (benchmarks/ is on the path when it is run)
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.utilities import try_shutdown
from std_srvs.srv import Trigger

from host_sdk.framing import Frame, FrameDecoder
from host_sdk.transport import Transport, open_transport
from protocol.generated.messages import Feedback, SetWheelSpeeds
from roverlink.ros2.interfaces import activate, is_built
from roverlink.ros2.node import BridgeNode

ROOT = Path(__file__).resolve().parents[1]
os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
os.environ.setdefault("ROS_DOMAIN_ID", str(1 + os.getpid() % 100))
RATE_HZ = 50


# == the minimal peer: Twist in, Odometry out at 50 Hz ==============================================
def relay_main() -> int:
    rclpy.init()
    node = Node("relay", namespace="/relay")
    pub = node.create_publisher(Odometry, "odom", 10)
    state = {"v": 0.0, "w": 0.0, "x": 0.0, "y": 0.0, "th": 0.0}

    def on_twist(msg: Any) -> None:
        state["v"], state["w"] = msg.linear.x, msg.angular.z

    def tick() -> None:
        dt = 1.0 / RATE_HZ
        state["th"] += state["w"] * dt
        state["x"] += state["v"] * dt * math.cos(state["th"])
        state["y"] += state["v"] * dt * math.sin(state["th"])
        msg = Odometry()
        msg.header.stamp = node.get_clock().now().to_msg()
        msg.header.frame_id, msg.child_frame_id = "odom", "base_link"
        msg.pose.pose.position.x, msg.pose.pose.position.y = state["x"], state["y"]
        msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(state["th"] / 2), math.cos(state["th"] / 2)
        msg.twist.twist.linear.x, msg.twist.twist.angular.z = state["v"], state["w"]
        pub.publish(msg)

    node.create_subscription(Twist, "cmd_vel", on_twist, 10)
    node.create_timer(1.0 / RATE_HZ, tick)
    with contextlib.suppress(KeyboardInterrupt):
        rclpy.spin(node)
    return 0


# == helpers ==========================================================================================
def cpu_s(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def spin(executor: Any, stop: threading.Event) -> threading.Thread:
    """Spin `executor` on a thread until `stop` is set."""

    def loop() -> None:
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.05)

    thread = threading.Thread(target=loop, daemon=True)
    thread.start()
    return thread


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def load_tf2_msgs() -> None:
    """Use tf2_msgs built into build/ros2 when it is not installed (for this process and children)."""
    if importlib.util.find_spec("tf2_msgs") is not None:
        return
    prefix = ROOT / "build" / "ros2"
    if is_built(prefix):
        activate(prefix)


@dataclass
class Tap:
    """Frames written and read by the bridge's transport, with their times."""

    setpoints: list[tuple[float, int, int]] = field(default_factory=list)
    """(time, seq, left_mm_s) of every SET_WHEEL_SPEEDS written."""
    feedback: list[tuple[float, int]] = field(default_factory=list)
    """(time, ack_seq) of every FEEDBACK read."""
    lock: threading.Lock = field(default_factory=threading.Lock)


def tapped(inner: Any, tap: Tap) -> Any:
    class TapTransport(Transport):
        def __init__(self) -> None:
            self.url, self.virtual = inner.url, inner.virtual
            self.profile, self.device = inner.profile, inner.device
            self._rx, self._tx = FrameDecoder(), FrameDecoder()

        def read(self, timeout_s: float) -> bytes:
            data: bytes = inner.read(timeout_s)
            now = time.monotonic()
            for event in self._rx.feed(data):
                if isinstance(event, Frame) and isinstance(event.message, Feedback):
                    with tap.lock:
                        tap.feedback.append((now, event.message.ack_seq))
            return data

        def write(self, data: bytes) -> None:
            now = time.monotonic()
            for event in self._tx.feed(data):
                if isinstance(event, Frame) and isinstance(event.message, SetWheelSpeeds):
                    with tap.lock:
                        tap.setpoints.append((now, event.seq, event.message.left_mm_s))
            inner.write(data)

        def close(self) -> None:
            inner.close()

        def clock(self) -> float:
            return float(inner.clock())

        def __getattr__(self, name: str) -> Any:
            return getattr(inner, name)

    return TapTransport()


# == 1. latency ========================================================================================
def measure_latency(mode: str, commands: int) -> dict[str, float]:
    tap = Tap()

    class TappedBridge(BridgeNode):
        def _connect(self, transport: Any = None) -> Any:
            return super()._connect(tapped(open_transport(self.params.url, self.params.baud), tap))

    bridge = TappedBridge({"url": "emu://diffdrive-tb6612", "mode": mode, "odom_rate": RATE_HZ})
    pub_node = Node("latency_pub")
    executor = SingleThreadedExecutor()
    executor.add_node(bridge)
    stop = threading.Event()
    thread = spin(executor, stop)
    try:
        deadline = time.monotonic() + 10
        while bridge.connection.robot is None and time.monotonic() < deadline:
            time.sleep(0.05)
        robot = bridge.connection.robot
        assert robot is not None, "the bridge did not connect"
        robot.arm()
        pub = pub_node.create_publisher(Twist, "/cmd_vel", 10)
        deadline = time.monotonic() + 10
        while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
            time.sleep(0.05)
        published: list[tuple[float, int]] = []
        for k in range(commands):
            mm = 100 + k % 200  # a distinct speed per command (wraps after 200)
            msg = Twist()
            msg.linear.x = mm / 1000
            published.append((time.monotonic(), mm))
            pub.publish(msg)
            time.sleep(0.05)  # pacing the publisher at 20 Hz
        time.sleep(0.3)
    finally:
        stop.set()
        thread.join(5)
        bridge.close()
        executor.shutdown()
        bridge.destroy_node()
        pub_node.destroy_node()
    with tap.lock:
        setpoints, feedback = list(tap.setpoints), list(tap.feedback)
    latencies = []
    for t_pub, mm in published:
        sent = next(((t, seq) for t, seq, left in setpoints if t >= t_pub and left == mm), None)
        if sent is None:
            continue
        applied = next((t for t, ack in feedback if t >= sent[0] and (ack - sent[1]) % 256 < 128), None)
        if applied is not None:
            latencies.append(applied - t_pub)
    if len(latencies) < 0.9 * commands:
        raise SystemExit(f"BENCHMARK INVALID: only {len(latencies)} of {commands} commands were seen applied")
    return {
        "commands": len(latencies),
        "p50_ms": percentile(latencies, 0.5) * 1e3,
        "p99_ms": percentile(latencies, 0.99) * 1e3,
        "max_ms": max(latencies) * 1e3,
    }


# == 2 and 3. rate, jitter, CPU ========================================================================
def start(args: list[str], **kw: Any) -> subprocess.Popen[str]:
    return subprocess.Popen(args, cwd=ROOT, text=True, **kw)


def _start_stack() -> list[subprocess.Popen[str]]:
    """The emulator on a pty, the bridge in /bridge on it, and the minimal relay (in that order)."""
    emulator = start(
        [sys.executable, "-m", "roverlink", "emulate", "--profile", "diffdrive-tb6612", "--eeprom", "saved", "--quiet"],
        stdout=subprocess.PIPE,
    )
    assert emulator.stdout is not None
    port = emulator.stdout.readline().strip()
    bridge_args = ["--url", port, "--profile", "diffdrive-tb6612", "--ros-args", "-r", "__ns:=/bridge"]
    bridge = start(
        [sys.executable, "-m", "roverlink", "ros2", *bridge_args, "-p", f"odom_rate:={RATE_HZ}"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    relay = start([sys.executable, __file__, "--relay"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return [emulator, bridge, relay]


def _arm_bridge(arm: Any) -> None:
    """Calls ~/arm until it succeeds: the bridge connects (through the board's bootloader) after
    its services are up."""
    if not arm.wait_for_service(timeout_sec=20):
        raise SystemExit("BENCHMARK INVALID: the bridge did not come up")
    deadline = time.monotonic() + 15
    while True:
        future = arm.call_async(Trigger.Request())
        while not future.done() and time.monotonic() < deadline:
            time.sleep(0.05)
        if future.done() and future.result().success:
            return
        if time.monotonic() > deadline:
            raise SystemExit("BENCHMARK INVALID: arming the bridge failed")
        time.sleep(0.2)


def _drive(pubs: list[Any], until: float) -> None:
    """cmd_vel at 20 Hz to every publisher: forward, weaving."""
    k = 0
    while time.monotonic() < until:
        msg = Twist()
        msg.linear.x, msg.angular.z = 0.2, 0.5 * math.sin(k / 20)
        for pub in pubs:
            pub.publish(msg)
        k += 1
        time.sleep(0.05)


def _stop(procs: list[subprocess.Popen[str]]) -> None:
    for proc in procs:
        proc.send_signal(2)
    for proc in procs:
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()


def _jitter(xs: list[float]) -> dict[str, float]:
    """|interval - nominal| over consecutive times, in ms."""
    nominal = 1.0 / RATE_HZ
    dev = [abs((b - a) - nominal) * 1e3 for a, b in itertools.pairwise(xs)]
    return {"mean_abs_ms": statistics.fmean(dev), "p99_abs_ms": percentile(dev, 0.99), "max_abs_ms": max(dev)}


def measure_processes(seconds: float) -> dict[str, Any]:
    emulator, bridge, relay = _start_stack()
    node = Node("bench")
    arrivals: dict[str, list[tuple[float, Any]]] = {"bridge": [], "relay": []}
    for name in arrivals:
        node.create_subscription(
            Odometry, f"/{name}/odom", lambda m, n=name: arrivals[n].append((time.monotonic(), m.header.stamp)), 50
        )
    pubs = [node.create_publisher(Twist, f"/{name}/cmd_vel", 10) for name in arrivals]
    arm = node.create_client(Trigger, "/bridge/roverlink/arm")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    stop = threading.Event()
    thread = spin(executor, stop)
    try:
        _arm_bridge(arm)
        _drive(pubs, time.monotonic() + 3.0)  # warm-up: discovery settled, the robot moving
        t0 = time.monotonic()
        cpu0 = {"bridge": cpu_s(bridge.pid), "relay": cpu_s(relay.pid)}
        _drive(pubs, t0 + seconds)
        t1 = time.monotonic()
        cpu1 = {"bridge": cpu_s(bridge.pid), "relay": cpu_s(relay.pid)}
    finally:
        stop.set()
        thread.join(5)
        _stop([relay, bridge, emulator])
        executor.shutdown()
        node.destroy_node()
    out: dict[str, Any] = {"seconds": t1 - t0}
    for name, items in arrivals.items():
        window = [(t, s) for t, s in items if t0 <= t <= t1]
        out[name] = {
            "odom_hz": len(window) / (t1 - t0),
            "cpu_percent": 100 * (cpu1[name] - cpu0[name]) / (t1 - t0),
            "stamp_interval_jitter": _jitter([s.sec + s.nanosec * 1e-9 for _, s in window]),
            "arrival_interval_jitter": _jitter([t for t, _ in window]),
        }
    out["cpu_ratio"] = out["bridge"]["cpu_percent"] / max(out["relay"]["cpu_percent"], 1e-9)
    return out


def loaded_main(seconds: float, hogs: int, out: Path | None, warn_only: bool, realtime: int = 0) -> int:
    rclpy.init()
    try:
        results = ros2_loaded.run(seconds, hogs, realtime=realtime)
    finally:
        try_shutdown()
    missed = ros2_loaded.report(results)
    if out is not None:
        out.write_text(json.dumps(results, indent=2))
    invalid = [text for text in missed if text.startswith("BENCHMARK INVALID")]
    for text in missed:
        print(text if text in invalid else f"GOAL MISSED: {text}")
    return 1 if invalid or (missed and not warn_only) else 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=None, help="window (default 15 s; --loaded: 600 s)")
    parser.add_argument("--commands", type=int, default=150, help="cmd_vel messages per latency run (default 150)")
    parser.add_argument("--json", type=Path, default=None, help="also write the figures to this file")
    parser.add_argument("--loaded", action="store_true", help="the SLAM robot with its sensors under busy loops")
    parser.add_argument("--hogs", type=int, default=os.cpu_count() or 2, help="--loaded: busy loops (one per core)")
    parser.add_argument("--warn-only", action="store_true", help="--loaded: a missed goal exits 0 (invalid runs 1)")
    parser.add_argument(
        "--realtime-priority",
        type=int,
        default=0,
        metavar="N",
        help="--loaded: the node's realtime_priority parameter (0: normal scheduling, the default)",
    )
    parser.add_argument("--relay", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.relay:
        return relay_main()
    load_tf2_msgs()
    if args.loaded:
        return loaded_main(args.seconds or 600.0, args.hogs, args.json, args.warn_only, args.realtime_priority)
    args.seconds = args.seconds or 15.0
    rclpy.init()
    try:
        results: dict[str, Any] = {"machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores"}
        for mode in ("stream", "lockstep"):
            results[f"latency_{mode}"] = measure_latency(mode, args.commands)
        results.update(measure_processes(args.seconds))
    finally:
        try_shutdown()
    print(f"ROS 2 bridge benchmark ({results['machine']}, Python {platform.python_version()})")
    for mode in ("stream", "lockstep"):
        r = results[f"latency_{mode}"]
        print(
            f"cmd_vel -> applied, {mode:<8}: p50 {r['p50_ms']:.1f} ms, p99 {r['p99_ms']:.1f} ms, "
            f"max {r['max_ms']:.1f} ms ({r['commands']} commands)"
        )
    for name in ("bridge", "relay"):
        r = results[name]
        s, a = r["stamp_interval_jitter"], r["arrival_interval_jitter"]
        print(
            f"{name:<6}: odom {r['odom_hz']:.1f} Hz, CPU {r['cpu_percent']:.1f} % of a core; interval error "
            f"stamps mean {s['mean_abs_ms']:.3f} / p99 {s['p99_abs_ms']:.3f} ms, "
            f"arrivals mean {a['mean_abs_ms']:.3f} / p99 {a['p99_abs_ms']:.3f} ms"
        )
    print(f"CPU bridge / minimal relay: {results['cpu_ratio']:.2f}x (same run, {results['seconds']:.1f} s window)")
    if args.json is not None:
        args.json.write_text(json.dumps(results, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
