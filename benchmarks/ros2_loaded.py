"""The ROS 2 bridge on a loaded host: `python benchmarks/ros2.py --loaded` (benchmarks/README.md).

The SLAM robot as it runs on a robot: `roverlink emulate` in its own process on a pty with its
RPLIDAR A1 and JY901 on ptys of their own in a world, `roverlink ros2` on those three ports in
lockstep at 100 Hz, armed and turning on the spot (no walls hit), while busy-loop processes keep
every core busy. Over the window:

- failsafes, by reason, from the node's log (COMM_TIMEOUT: the board's watchdog saw no frame for
  0.25 s; the goal is none);
- odometry intervals on the board's clock (the `odom` header stamps: FEEDBACK's MCU time through
  the SDK's clock sync), in periods of odom_rate: the goal is p99.9 at most 1.5 periods;
- the scan stamps' error against the emulator's truth (`roverlink emulate --truth`: when the
  rotor passed the rear, where each LaserScan's ray 0 lies), and against the mean of their
  neighbours (the rotor's speed wanders by at most 1 % and slowly: for the truth under 10 us);
- CPU of the node and of the emulator;
- the floor any design on this host has: a lone thread in a process of its own (nice 0, like the
  node) waking once a period over the same window, and how often it woke later than a paced
  setpoint may be late before its tick is missed (`slack_ms`).
"""

from __future__ import annotations

import bisect
import itertools
import json
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import LaserScan

from host_sdk.session.setpoints import PACE_PHASE_S, TICK_S, slot_span_s
from protocol.framing import encode_frame
from protocol.generated.messages import SetWheelSpeeds

ROOT = Path(__file__).resolve().parents[1]
PROFILE = "diffdrive-bts7960"
ODOM_HZ = 100
GOAL_P999_PERIODS = 1.5
EMULATE = ["--profile", PROFILE, "--eeprom", "saved", "--seed", "2", "--world", "random:2"]
EMULATE += ["--lidar", "rplidar-a1", "--imu", "jy901"]
ROVERLINK = [sys.executable, "-m", "roverlink"]
_FAILSAFE = re.compile(r"board in FAILSAFE: (\w+)")
_LAG = re.compile(r"longest lag behind real time: (\d+) ms")
EMULATOR_FIFO_PRIORITY = 10
EMULATOR_NICE = -10
MAX_EMULATOR_LAG_MS = 100.0
"""A board model further behind real time fails safe on time it never had: the run is invalid."""


def _cpu_s(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, math.ceil(q * (len(ordered) - 1)))]


def _stamp_s(stamp: Any) -> float:
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9


BAUD = 115200
FRAME_S = len(encode_frame(SetWheelSpeeds(0, 0), 0)) * 10 / BAUD
SLACK_MS = (slot_span_s(TICK_S) - PACE_PHASE_S - FRAME_S) * 1e3
"""How late a paced setpoint may go out before a tick goes unanswered: sent PACE_PHASE_S after a
tick, a tick ahead in the board's queue, its frame on the wire at BAUD, it must land before the
tick after next."""
PROBE = """
import json, select, sys, time
period, seconds = float(sys.argv[1]), float(sys.argv[2])
late = []
t_next = time.monotonic() + period
t_end = t_next + seconds
while t_next < t_end:
    select.select([], [], [], max(0.0, t_next - time.monotonic()))
    late.append(time.monotonic() - t_next)
    t_next += period
print(json.dumps(late))
"""


def start_probe(seconds: float) -> subprocess.Popen[str]:
    """The floor: a lone thread waking once a period, as the SDK's I/O thread waits (select)."""
    args = [sys.executable, "-c", PROBE, str(1.0 / ODOM_HZ), str(seconds)]
    return subprocess.Popen(args, text=True, stdout=subprocess.PIPE)


def probe_figures(probe: subprocess.Popen[str]) -> dict[str, Any]:
    out, _ = probe.communicate(timeout=60)
    late_ms = [1e3 * x for x in json.loads(out)]
    return {
        "wakeups": len(late_ms),
        "p99_ms": _percentile(late_ms, 0.99),
        "p999_ms": _percentile(late_ms, 0.999),
        "max_ms": max(late_ms),
        "over_slack": sum(x > SLACK_MS for x in late_ms),
    }


def start_hogs(n: int) -> list[subprocess.Popen[bytes]]:
    """`n` processes that only spin: with one per core, every other thread competes for a core."""
    code = "while True: pass"
    return [subprocess.Popen([sys.executable, "-c", code]) for _ in range(n)]


def start_stack(log_dir: Path, realtime: int = 0) -> tuple[subprocess.Popen[str], subprocess.Popen[str], str]:
    """The emulator (its ports from its stdout) and the node on them (its `realtime_priority`),
    logging to `log_dir`; and how the emulator is scheduled."""
    cmd = [*ROVERLINK, "emulate", *EMULATE, "--truth", str(log_dir / "truth.jsonl")]
    emu_log = (log_dir / "emulate.log").open("w")
    emulator = subprocess.Popen(cmd, cwd=ROOT, text=True, stdout=subprocess.PIPE, stderr=emu_log)
    assert emulator.stdout is not None
    priority = _raise_priority(emulator.pid)
    port = emulator.stdout.readline().strip()
    ports = dict(emulator.stdout.readline().split()[::2] for _ in range(2))  # "lidar rplidar-a1 /dev/pts/N"
    params = {"odom_rate": ODOM_HZ, "auto_arm": "true", "lidar_url": ports["lidar"], "lidar_model": "rplidar-a1"}
    params["imu_url"] = ports["imu"]
    if realtime:
        params["realtime_priority"] = realtime
    args = [*ROVERLINK, "ros2", "--url", port, "--profile", PROFILE, "--ros-args"]
    args += ["-r", "__ns:=/loaded"]
    for key, value in params.items():
        args += ["-p", f"{key}:={value}"]
    bridge_log = (log_dir / "bridge.log").open("w")
    bridge = subprocess.Popen(args, cwd=ROOT, text=True, stdout=bridge_log, stderr=subprocess.STDOUT)
    return emulator, bridge, priority


def _raise_priority(pid: int) -> str:
    """The emulator stands for the board and the sensors, each with a CPU of its own: under
    SCHED_FIFO (or else at nice -10; either needs root or CAP_SYS_NICE) the busy loops load the
    host's software, not the model of the robot. Its lag behind real time is read from its log
    either way (`emulator_lag_ms`). Returns how it runs."""
    try:
        os.sched_setscheduler(pid, os.SCHED_FIFO, os.sched_param(EMULATOR_FIFO_PRIORITY))
        return f"SCHED_FIFO {EMULATOR_FIFO_PRIORITY}"
    except PermissionError:
        pass
    try:
        os.setpriority(os.PRIO_PROCESS, pid, EMULATOR_NICE)
        return f"nice {EMULATOR_NICE}"
    except PermissionError:
        return "nice 0 (no root or CAP_SYS_NICE)"


def _emulator_lag_ms(log: str) -> float | None:
    found = _LAG.findall(log)
    return float(found[-1]) if found else None


class Recorder(Node):
    """odom and scan stamps with their arrival times; cmd_vel out (a slow turn on the spot)."""

    def __init__(self) -> None:
        super().__init__("loaded_bench")
        self.lock = threading.Lock()
        self.odom: list[tuple[float, float]] = []
        self.scans: list[tuple[float, float]] = []
        self.create_subscription(Odometry, "/loaded/odom", self._on_odom, 200)
        self.create_subscription(LaserScan, "/loaded/scan", self._on_scan, qos_profile_sensor_data)
        self.cmd = self.create_publisher(Twist, "/loaded/cmd_vel", 10)
        self.paced_late: list[tuple[float, int]] = []
        """The node's own count of paced setpoints it sent late (its link status), as it rose."""
        self.create_subscription(DiagnosticArray, "/diagnostics", self._on_diagnostics, 10)

    def _on_odom(self, msg: Any) -> None:
        with self.lock:
            self.odom.append((time.monotonic(), _stamp_s(msg.header.stamp)))

    def _on_scan(self, msg: Any) -> None:
        with self.lock:
            self.scans.append((time.monotonic(), _stamp_s(msg.header.stamp)))

    def _on_diagnostics(self, msg: Any) -> None:
        for status in msg.status:
            if status.name.endswith(": link"):
                values = {v.key: v.value for v in status.values}
                if "host paced_late" in values:
                    with self.lock:
                        self.paced_late.append((time.monotonic(), int(values["host paced_late"])))

    def drive(self, k: int) -> None:
        msg = Twist()
        msg.angular.z = 0.8 * math.sin(k / 40)  # turning on the spot, back and forth: the scan sweeps
        self.cmd.publish(msg)


def odom_figures(stamps: list[float]) -> dict[str, Any]:
    period = 1.0 / ODOM_HZ
    gaps = [(b - a) / period for a, b in itertools.pairwise(stamps)]
    return {
        "messages": len(stamps),
        "rate_hz": (len(stamps) - 1) / (stamps[-1] - stamps[0]),
        "p50_periods": _percentile(gaps, 0.5),
        "p99_periods": _percentile(gaps, 0.99),
        "p999_periods": _percentile(gaps, 0.999),
        "max_periods": max(gaps),
        "over_1_5": sum(g > 1.5 for g in gaps),
        "intervals": len(gaps),
    }


def scan_figures(stamps: list[float]) -> dict[str, Any]:
    """Each stamp against the mean of its neighbours (ms)."""
    err = [abs(b - (a + c) / 2) * 1e3 for a, b, c in zip(stamps, stamps[1:], stamps[2:], strict=False)]
    if not err:
        return {"scans": len(stamps)}
    return {
        "scans": len(stamps),
        "rate_hz": (len(stamps) - 1) / (stamps[-1] - stamps[0]),
        "mean_ms": statistics.fmean(err),
        "p99_ms": _percentile(err, 0.99),
        "max_ms": max(err),
    }


def truth_figures(stamps: list[float], rears: list[float]) -> dict[str, Any]:
    """Each stamp (on CLOCK_MONOTONIC) against the nearest of the emulator's true times of ray 0
    (ms): what a SLAM node would use the scan at, against when it was measured."""
    err = []
    for s in stamps:
        i = bisect.bisect_left(rears, s)
        near = [rears[j] for j in (i - 1, i) if 0 <= j < len(rears)]
        if near:
            err.append((s - min(near, key=lambda r: abs(r - s))) * 1e3)
    if not err:
        return {}
    size = [abs(e) for e in err]
    return {
        "truth_mean_ms": statistics.fmean(err),
        "truth_p99_ms": _percentile(size, 0.99),
        "truth_max_ms": max(size),
        "truth_over_10_ms": sum(e > 10.0 for e in size),
    }


def _rears(log_dir: Path) -> list[float]:
    """The emulator's truth file: when its lidar passed the rear (CLOCK_MONOTONIC)."""
    path = log_dir / "truth.jsonl"
    if not path.exists():
        return []
    return sorted(json.loads(line)["lidar_rear_s"] for line in path.read_text().splitlines() if line.strip())


def run(seconds: float, hogs: int, warmup_s: float = 3.0, realtime: int = 0) -> dict[str, Any]:
    log_dir = Path(tempfile.mkdtemp(prefix="roverlink-loaded-"))
    emulator, bridge, priority = start_stack(log_dir, realtime)
    node = Recorder()
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    stop = threading.Event()

    def spin() -> None:
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.05)

    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()
    loaders: list[subprocess.Popen[bytes]] = []
    k = 0
    try:
        # Connected, armed (auto_arm: lockstep FEEDBACK then answers the setpoints) and turning
        # for `warmup_s` before the load starts.
        t_end = time.monotonic() + 60.0
        while time.monotonic() < t_end:
            node.drive(k)
            k += 1
            time.sleep(0.05)
            with node.lock:
                if node.odom and t_end - time.monotonic() > warmup_s:
                    t_end = time.monotonic() + warmup_s
        loaders = start_hogs(hogs)
        realtime_offset = time.time() - time.monotonic()  # the stamps' clock (the system's) to monotonic
        probe = start_probe(seconds)
        t0 = time.monotonic()
        cpu0 = (_cpu_s(bridge.pid), _cpu_s(emulator.pid))
        while time.monotonic() < t0 + seconds:
            node.drive(k)
            k += 1
            time.sleep(0.05)
        t1 = time.monotonic()
        cpu1 = (_cpu_s(bridge.pid), _cpu_s(emulator.pid))
    finally:
        for proc in loaders:
            proc.kill()
        stop.set()
        spinner.join(5)
        for proc in (bridge, emulator):
            proc.send_signal(2)
        for proc in (bridge, emulator):
            try:
                proc.wait(15)
            except subprocess.TimeoutExpired:
                proc.kill()
        executor.shutdown()
        node.destroy_node()
    floor = probe_figures(probe)
    log = (log_dir / "bridge.log").read_text()
    lag = _emulator_lag_ms((log_dir / "emulate.log").read_text())
    with node.lock:
        odom = [s for t, s in node.odom if t0 <= t <= t1]
        late = [n for t, n in node.paced_late if t0 <= t <= t1 + 1.0]
        scans = [s for t, s in node.scans if t0 <= t <= t1]
    if len(odom) < 0.05 * ODOM_HZ * seconds:
        raise SystemExit(f"BENCHMARK INVALID: {len(odom)} odom messages in {seconds:.0f} s (logs: {log_dir})")
    return {
        "seconds": t1 - t0,
        "hogs": hogs,
        "logs": str(log_dir),
        "failsafes": dict(Counter(_FAILSAFE.findall(log))),
        "emulator_lag_ms": lag,
        "emulator_priority": priority,
        "node_realtime_priority": realtime,
        "odom": odom_figures(odom),
        "scan": scan_figures(scans) | truth_figures([s - realtime_offset for s in scans], _rears(log_dir)),
        "floor": floor,
        "paced_late": late[-1] - late[0] if len(late) > 1 else None,
        "cpu_percent": {
            "bridge": 100 * (cpu1[0] - cpu0[0]) / (t1 - t0),
            "emulator": 100 * (cpu1[1] - cpu0[1]) / (t1 - t0),
        },
    }


def report(r: dict[str, Any]) -> list[str]:
    """The figures in words, and what misses a goal (empty: every goal met)."""
    o, s, c = r["odom"], r["scan"], r["cpu_percent"]
    failsafes = ", ".join(f"{n} {why}" for why, n in r["failsafes"].items()) or "none"
    print(f"loaded: {r['hogs']} busy loops, {r['seconds']:.0f} s, {PROFILE} lockstep at {ODOM_HZ} Hz")
    print(f"logs: {r['logs']}")
    print(f"failsafes: {failsafes}")
    print(
        f"odom: {o['rate_hz']:.2f} Hz; intervals in periods p50 {o['p50_periods']:.2f}, p99 {o['p99_periods']:.2f}, "
        f"p99.9 {o['p999_periods']:.2f}, max {o['max_periods']:.2f}; {o['over_1_5']} of {o['intervals']} over 1.5"
    )
    if "mean_ms" in s:
        print(
            f"scan: {s['scans']} at {s['rate_hz']:.2f} Hz; stamp error against its neighbours' mean "
            f"mean {s['mean_ms']:.2f} ms, p99 {s['p99_ms']:.2f} ms, max {s['max_ms']:.2f} ms"
        )
    if "truth_mean_ms" in s:
        print(
            f"scan stamps against the emulator's truth (ray 0 measured): mean {s['truth_mean_ms']:+.2f} ms, "
            f"p99 {s['truth_p99_ms']:.2f} ms, max {s['truth_max_ms']:.2f} ms; {s['truth_over_10_ms']} over 10 ms"
        )
    print(f"CPU: node {c['bridge']:.0f} %, emulator {c['emulator']:.0f} % of a core")
    if r["paced_late"] is not None:
        print(f"the node's paced setpoints sent half their slack or more late: {r['paced_late']}")
    f = r["floor"]
    print(
        f"floor: a lone thread waking every period, late p99 {f['p99_ms']:.2f} ms, p99.9 {f['p999_ms']:.2f} ms, "
        f"max {f['max_ms']:.2f} ms; {f['over_slack']} of {f['wakeups']} later than the {SLACK_MS:.1f} ms slack"
    )
    print(f"emulator ({r['emulator_priority']}): longest lag behind real time {r['emulator_lag_ms']} ms")
    rt = r["node_realtime_priority"]
    print(f"node: {f'every thread under SCHED_FIFO {rt}' if rt else 'normal scheduling (nice 0)'}")
    missed = []
    lag = r["emulator_lag_ms"]
    if lag is None or lag > MAX_EMULATOR_LAG_MS:
        most = f"at most {MAX_EMULATOR_LAG_MS:.0f}"
        missed.append(f"BENCHMARK INVALID: the emulator fell {lag} ms behind real time ({most})")
    if r["failsafes"].get("COMM_TIMEOUT"):
        missed.append(f"{r['failsafes']['COMM_TIMEOUT']} COMM_TIMEOUT failsafes (goal: none)")
    if o["p999_periods"] > GOAL_P999_PERIODS:
        missed.append(f"odom p99.9 interval {o['p999_periods']:.2f} periods (goal: at most {GOAL_P999_PERIODS})")
    return missed
