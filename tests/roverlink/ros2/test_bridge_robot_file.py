"""`roverlink ros2 --robot FILE`: the node's odometry and cmd_vel use the file's geometry.

A robot file copied from the TB6612 robot with 0.25 m of track (the reference's is 0.2 m), a
feedback rate of 100 Hz (the reference's 50 Hz; the node takes it, no odom_rate given) and a
name of its own: against `emu://diffdrive-tb6612` the node emulates the file's robot (its name on
the board says so), and a turn in place comes out right in odometry, where the reference
profile's track would be 25 % off.
"""

from __future__ import annotations

import math
import time
import uuid
from pathlib import Path
from typing import Any

import pytest
from ros_env import require_ros

require_ros()

from bridge_harness import BridgeProcess, Probe, logged, values, yaw  # noqa: E402

from protocol.robotfile import reference_path  # noqa: E402
from tests.support.wait import wait_until  # noqa: E402


def wide_bridge(tmp_path: Path) -> tuple[BridgeProcess, Probe]:
    """The node with a robot file saying 0.25 m of track, against the emulated TB6612 robot's URL."""
    text = reference_path("diffdrive-tb6612").read_text(encoding="utf-8")
    assert text.count("\ntrack_m = 0.2 ") == 1
    path = tmp_path / "wide.toml"
    assert text.count('name = "diffdrive-tb6612"') == 1
    text = text.replace('name = "diffdrive-tb6612"', 'name = "wide_tb6612"')
    assert text.count("rate_hz = 50.0 ") == 1
    text = text.replace("rate_hz = 50.0 ", "rate_hz = 100.0 ")  # no odom_rate given: the node takes this
    path.write_text(text.replace("\ntrack_m = 0.2 ", "\ntrack_m = 0.25 "), encoding="utf-8")
    ns = f"/robot_file_{uuid.uuid4().hex[:6]}"
    proc = BridgeProcess(ns, "emu://diffdrive-tb6612?seed=1", tmp_path, robot_file=path)
    return proc, Probe(ns)


def armed(probe: Probe) -> None:
    probe.wait_for("the bridge's services", lambda: probe.clients["arm"].wait_for_service(timeout_sec=0.1), 20)
    probe.wait_status("robot", lambda s: values(s).get("robot") == "wide_tb6612", 20)
    assert probe.call("arm").success


def test_odometry_uses_the_files_track(ros: None, tmp_path: Path) -> None:
    proc, probe = wide_bridge(tmp_path)
    with logged(proc, probe):
        armed(probe)
        assert "stream feedback at 100 Hz" in proc.log()
        start = yaw(probe.wait_message("truth").pose.pose.orientation)
        odom_start = yaw(probe.wait_message("odom").pose.pose.orientation)
        probe.drive(0.0, 1.0, 1.5)
        probe.drive(0.0, 0.0, 0.3)

        def still() -> object:
            recent = probe.since("odom", time.monotonic() - 0.3)
            ok = len(recent) >= 3 and all(abs(r.msg.twist.twist.angular.z) < 1e-3 for r in recent)
            return recent[-1].msg if ok else None

        odom = probe.wait_for("the robot to stand still", still, 5)
        truth = probe.wait_message("truth", after=time.monotonic())
        turned = math.degrees(math.remainder(yaw(truth.pose.pose.orientation) - start, math.tau))
        odom_turned = math.degrees(math.remainder(yaw(odom.pose.pose.orientation) - odom_start, math.tau))
        assert turned > 45, turned
        assert odom_turned == pytest.approx(turned, abs=1.0)  # the reference track: a quarter off


def _stop(probe: Probe) -> Any:
    """Command zero until odometry has stood still for 0.3 s; returns that odometry."""

    def still() -> object:
        probe.twist(0.0, 0.0)
        recent = probe.since("odom", time.monotonic() - 0.3)
        twist = [r.msg.twist.twist for r in recent]
        ok = len(recent) >= 3 and all(abs(t.linear.x) < 1e-3 and abs(t.angular.z) < 1e-3 for t in twist)
        return recent[-1].msg if ok else None

    return probe.wait_for("the robot to stand still", still, 10)


def _drive_until(probe: Probe, linear: float, angular: float, done: Any, timeout_s: float) -> None:
    """Publish the twist at 20 Hz until `done(odom)` holds for the latest odometry."""
    wait_until(
        lambda: done(probe.last("odom")),
        timeout_s,
        f"odometry done driving ({linear}, {angular})",
        step=lambda: probe.drive(linear, angular, 0.05),
    )


def _pose(msg: Any) -> tuple[float, float, float]:
    p = msg.pose.pose
    return p.position.x, p.position.y, yaw(p.orientation)


def _error(probe: Probe) -> tuple[Any, float, float]:
    """At a standstill: odometry, and its position (m) and heading (rad) error against the truth."""
    odom = _stop(probe)
    truth = probe.wait_message("truth", after=time.monotonic())
    (ox, oy, oth), (tx, ty, tth) = _pose(odom), _pose(truth)
    return odom, math.hypot(ox - tx, oy - ty), math.remainder(oth - tth, math.tau)


def test_a_square_and_a_full_turn_within_one_percent_with_the_files_track(ros: None, tmp_path: Path) -> None:
    """The emulated robot is the file's, 0.25 m of track (the reference's: 0.2 m). Odometry (the node's, through the file) ends within 1 % of the distance
    driven of the emulator's ground truth: a 1 m square, then a turn in place of 360 degrees."""
    proc, probe = wide_bridge(tmp_path)
    with logged(proc, probe):
        armed(probe)
        odom, _, _ = _error(probe)
        for _side in range(4):
            x0, y0, th0 = _pose(odom)
            _drive_until(probe, 0.3, 0.0, lambda m, x0=x0, y0=y0: math.dist(_pose(m)[:2], (x0, y0)) >= 1.0, 15)
            _stop(probe)
            turned = lambda m, th0=th0: math.remainder(_pose(m)[2] - th0, math.tau) >= math.pi / 2  # noqa: E731
            _drive_until(probe, 0.0, 0.8, turned, 10)
            odom, position_error, heading_error = _error(probe)
        print(f"square: position error {position_error * 1000:.1f} mm, heading {math.degrees(heading_error):.2f} deg")
        assert position_error < 0.01 * 4.0
        truth_start = _pose(probe.wait_message("truth", after=time.monotonic()))[2]
        odom_start, swept = _pose(odom)[2], [0.0, _pose(odom)[2]]

        def full_turn(m: Any) -> bool:
            swept[0] += math.remainder(_pose(m)[2] - swept[1], math.tau)
            swept[1] = _pose(m)[2]
            return swept[0] >= math.tau

        _drive_until(probe, 0.0, 1.0, full_turn, 20)
        odom, _, _ = _error(probe)
        truth_end = _pose(probe.wait_message("truth", after=time.monotonic()))[2]
        turn_error = math.remainder((_pose(odom)[2] - odom_start) - (truth_end - truth_start), math.tau)
        print(f"360 degree turn: heading error {math.degrees(turn_error):.2f} deg")
        assert abs(turn_error) < 0.01 * math.tau
