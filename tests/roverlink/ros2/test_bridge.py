"""`roverlink ros2` end to end: a real bridge process against the emulator (emu://, real clock) and
a test node talking to it over DDS, for each reference robot (the SLAM robot in lockstep mode).

Odometry is compared with the emulator's ground truth within the tolerances of the SDK's own
suite (tests/system/integration/test_integration_emulator.py): differential drives 10 mm and 0.5 deg,
the PiCar 20 mm and 2 deg. Rates are checked on the header stamps, which come from the MCU's
clock, so a busy test machine does not make them flaky.
"""

from __future__ import annotations

import itertools
import math
import signal
import statistics
import time
import uuid
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from ros_env import require_ros

require_ros()

from bridge_harness import ROOT, BridgeProcess, Probe, logged, stamp_s, values, yaw  # noqa: E402
from rcl_interfaces.srv import GetParameters  # noqa: E402
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy  # noqa: E402
from std_msgs.msg import String  # noqa: E402
from std_srvs.srv import SetBool, Trigger  # noqa: E402

from host_sdk.profiles import get_profile  # noqa: E402
from host_sdk.robot_description import RobotDescription  # noqa: E402
from protocol.robotfile import reference_path  # noqa: E402
from tests.support.wait import wait_until  # noqa: E402


@dataclass(frozen=True)
class Case:
    profile: str
    tol_m: float
    tol_deg: float
    lockstep: bool
    ackermann: bool
    example: str


CASES = {
    "diffdrive-tb6612": Case("diffdrive-tb6612", 0.010, 0.5, False, False, "DiffDriveTB6612"),
    "diffdrive-bts7960": Case("diffdrive-bts7960", 0.010, 0.5, True, False, "DiffDriveBTS7960"),
    "picar": Case("picar", 0.020, 2.0, False, True, "AckermannPiCar"),
}
PARAMS_YAML = ROOT / "examples" / "ros2" / "roverlink.yaml"
WATCHDOG_S = 0.25
CMD_VEL_TIMEOUT_S = 0.5


@dataclass
class Bridge:
    case: Case
    proc: BridgeProcess
    probe: Probe

    def turn(self, angular: float, linear: float) -> float:
        """cmd_vel angular rate for this robot: the PiCar turns with its steering at one 15-degree step."""
        if not self.case.ackermann:
            return angular
        wheelbase = get_profile(self.case.profile).wheelbase_m
        return math.copysign(linear * math.tan(math.radians(15)) / wheelbase, angular) if angular else 0.0


@pytest.fixture(scope="module", params=list(CASES))
def bridge(request: pytest.FixtureRequest, ros: None, tmp_path_factory: pytest.TempPathFactory) -> Iterator[Bridge]:
    case = CASES[request.param]
    ns = f"/{case.profile.replace('-', '_')}_{uuid.uuid4().hex[:6]}"
    # Every bridge loads the example parameters file; --url and --profile win over it.
    extra = ["--params-file", str(PARAMS_YAML)]
    url = f"emu://{case.profile}?seed=1"
    proc = BridgeProcess(ns, url, tmp_path_factory.mktemp("ros2"), extra=extra, profile=case.profile)
    probe = Probe(ns)
    with logged(proc, probe):
        probe.wait_for("the bridge's services", lambda: probe.clients["arm"].wait_for_service(timeout_sec=0.1), 20)
        probe.wait_status("robot", lambda s: values(s).get("robot") == case.example, 20)
        yield Bridge(case, proc, probe)


def arm(probe: Probe) -> None:
    answer = probe.call("arm")
    assert answer.success, answer.message


def drive_until_moving(bridge: Bridge, timeout_s: float = 8.0) -> None:
    """The PiCar's ESC holds neutral for its first 3 s after boot: wait until the robot really moves."""
    probe = bridge.probe
    start = [probe.last("truth")]

    def moved() -> bool:
        now = probe.last("truth")
        if start[0] is not None and now is not None:
            return bool(now.pose.pose.position.x - start[0].pose.pose.position.x > 0.01)
        start[0] = start[0] or now
        return False

    wait_until(moved, timeout_s, "the robot to move", step=lambda: probe.drive(0.2, 0.0, 0.2))


def wait_still(probe: Probe, timeout_s: float = 5.0) -> Any:
    """Wait until odometry reports zero speed for a few samples; returns the last odom."""

    def still() -> Any:
        recent = probe.since("odom", time.monotonic() - 0.3)
        ok = len(recent) >= 3 and all(abs(r.msg.twist.twist.linear.x) < 1e-3 for r in recent)
        return recent[-1].msg if ok else None

    return probe.wait_for("the robot to stand still", still, timeout_s)


def wait_truth_still(probe: Probe, timeout_s: float = 5.0) -> Any:
    """Wait until the emulator's ground truth stops moving; returns its last message."""

    def still() -> Any:
        recent = [r.msg.pose.pose.position for r in probe.since("truth", time.monotonic() - 0.3)]
        moved = max((math.hypot(p.x - recent[0].x, p.y - recent[0].y) for p in recent), default=1.0)
        return probe.last("truth") if len(recent) >= 4 and moved < 1e-4 else None

    return probe.wait_for("the emulated robot to stand still", still, timeout_s)


def test_odom_joint_states_and_diagnostics_arrive_at_their_rates(bridge: Bridge) -> None:
    probe, case = bridge.probe, bridge.case
    arm(probe)  # lockstep: FEEDBACK (so odometry) flows while the node commands an armed robot
    # odom_rate 0 in the example file: the robot's own feedback rate (the BTS7960 robot's is 100 Hz)
    rate = round(RobotDescription.load(reference_path(case.profile)).feedback.rate_hz)
    t0 = probe.wait_for("odom", lambda: (probe.since("odom") or [None])[-1]).at
    probe.wait_for("2 s of odom", lambda: time.monotonic() > t0 + 2.0, 5)
    for key in ("odom", "joint_states"):
        msgs = [r.msg for r in probe.since(key, t0)]
        stamps = [stamp_s(m.header.stamp) for m in msgs]
        gaps = [b - a for a, b in itertools.pairwise(stamps)]
        assert all(g > 0 for g in gaps), f"{key} stamps go back"
        assert statistics.median(gaps) == pytest.approx(1 / rate, rel=0.1), f"{key} is not at {rate} Hz"
        assert len(msgs) >= 0.6 * rate * 2.0
        # Stamped when the board sampled, before the FEEDBACK crossed the 115200 baud line (3.5 ms
        # for its 40 bytes, plus the adapter's 1 ms; 5-6 ms measured), not when it was read
        # (DDS delivery alone takes well under a millisecond here).
        ages = [r.ros_s - stamp_s(r.msg.header.stamp) for r in probe.since(key, t0)]
        assert statistics.median(ages) > 0.003, f"{key} is stamped when read, not when sampled"
    odom = probe.last("odom")
    assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_link")
    assert len(odom.pose.covariance) == 36 and odom.pose.covariance[0] == pytest.approx(0.001)
    joints = probe.last("joint_states")
    expected = ["rear_wheel_joint", "steering_joint"] if case.ackermann else ["left_wheel_joint", "right_wheel_joint"]
    assert list(joints.name) == expected and len(joints.position) == len(joints.velocity) == len(expected)
    # Diagnostics at 1 Hz: both statuses, with identity, link counters, rates, RTT and clock sync.
    probe.wait_for("3 diagnostics reports", lambda: len(probe.since("diagnostics", t0)) >= 3, 6)
    arrivals = [r.at for r in probe.since("diagnostics", t0)]
    assert all(0.5 < b - a < 1.6 for a, b in itertools.pairwise(arrivals))
    link, robot = values(probe.status("link")), values(probe.status("robot"))
    # OK, or WARN for the host's own lateness alone (a loaded CI host sends a lockstep period late
    # now and then, and the node says so); any link error counter rising fails.
    status = probe.status("link")
    rising = status.message.removeprefix("link errors rising: ").split(", ")
    host_late_only = status.level == b"\x01" and all(r.startswith("host paced_late +") for r in rising)
    assert status.level == b"\x00" or host_late_only, status.message
    assert link["feedback mode"] == ("lockstep" if case.lockstep else "stream")
    assert float(link["feedback rate (Hz)"]) == pytest.approx(rate, rel=0.25)
    for key in ("rtt last/min/mean/max (ms)", "clock drift (ppm)", "host frames received/s", "board frames sent/s"):
        assert key in link, key
    assert robot["firmware"] and robot["state"] == "armed" and robot["failsafe"] == "-"


def test_cmd_vel_drives_and_odom_follows_ground_truth(bridge: Bridge, tf2_msgs: Path) -> None:
    from tf2_msgs.msg import TFMessage

    probe, case = bridge.probe, bridge.case
    probe.subscribe("tf", TFMessage, "tf", 100)
    arm(probe)
    if case.ackermann:
        drive_until_moving(bridge)
    start = probe.last("truth").pose.pose.position
    spin = 0.2 if case.ackermann else 0.0  # an Ackermann robot cannot turn in place
    for seconds, v, w in [(1.2, 0.4, 0.0), (1.2, 0.3, 0.6), (1.2, 0.3, -0.5), (0.8, spin, 1.0)]:
        probe.drive(v, bridge.turn(w, v), seconds)
    probe.drive(0.0, 0.0, 0.3)
    odom = wait_still(probe)
    truth = probe.wait_message("truth", after=time.monotonic())
    t, o = truth.pose.pose, odom.pose.pose
    assert math.hypot(t.position.x - start.x, t.position.y - start.y) > 1.0, "the robot hardly moved"
    error_m = math.hypot(o.position.x - t.position.x, o.position.y - t.position.y)
    error_deg = math.degrees(abs(math.remainder(yaw(o.orientation) - yaw(t.orientation), math.tau)))
    assert error_m <= case.tol_m and error_deg <= case.tol_deg, (error_m, error_deg)
    # /tf carries the same pose at the same stamp (built with a real tf2_msgs and received over DDS).
    tf = probe.wait_for("a transform at the odom stamp", lambda: _transform_at(probe, odom.header.stamp), 3)
    assert (tf.header.frame_id, tf.child_frame_id) == ("odom", "base_link")
    assert (tf.transform.translation.x, tf.transform.translation.y) == (o.position.x, o.position.y)
    assert yaw(tf.transform.rotation) == pytest.approx(yaw(o.orientation), abs=1e-9)


def _transform_at(probe: Probe, stamp: Any) -> Any:
    for r in reversed(probe.since("tf")):
        for tf in r.msg.transforms:
            if (tf.header.stamp.sec, tf.header.stamp.nanosec) == (stamp.sec, stamp.nanosec):
                return tf
    return None


def test_silence_stops_the_robot_within_the_timeout_and_watchdog(bridge: Bridge) -> None:
    probe, case = bridge.probe, bridge.case
    arm(probe)
    probe.drive(0.3, 0.0, 1.0)
    last_publish_ros = probe.node.get_clock().now().nanoseconds * 1e-9
    decel = get_profile(case.profile).config.decel_limit_mm_s2 / 1000
    bound = CMD_VEL_TIMEOUT_S + WATCHDOG_S + 0.3 / decel + 0.05
    odom = wait_still(probe, 5.0)
    first_still = next(
        r.msg
        for r in probe.since("odom")
        if stamp_s(r.msg.header.stamp) > last_publish_ros and abs(r.msg.twist.twist.linear.x) < 1e-3
    )
    assert stamp_s(first_still.header.stamp) - last_publish_ros <= bound
    assert abs(odom.twist.twist.linear.x) < 1e-3
    # The default on_timeout=stop holds zero speed: still armed, no failsafe.
    status = probe.wait_status("robot", lambda s: True)
    assert values(status)["state"] == "armed" and status.level == b"\x00", status.message


def test_failsafe_appears_in_diagnostics_until_armed_again(bridge: Bridge) -> None:
    probe = bridge.probe
    arm(probe)
    probe.wait_status("robot", lambda s: values(s)["state"] == "armed")
    assert probe.call("cut_link", SetBool.Request(data=True)).success
    probe.wait_status("link", lambda s: s.message.startswith("no FEEDBACK") and s.level == b"\x02", 4)
    assert probe.call("cut_link", SetBool.Request(data=False)).success
    status = probe.wait_status("robot", lambda s: s.level == b"\x02", 4)
    assert "FAILSAFE (COMM_TIMEOUT)" in status.message and values(status)["failsafe"] == "COMM_TIMEOUT"
    assert int(values(status)["failsafes"]) >= 1
    arm(probe)
    status = probe.wait_status("robot", lambda s: s.level == b"\x00", 4)
    assert values(status)["state"] == "armed"


def test_board_reset_appears_in_diagnostics_and_odometry_continues(bridge: Bridge) -> None:
    probe, case = bridge.probe, bridge.case
    arm(probe)
    drive_until_moving(bridge)
    probe.drive(0.0, 0.0, 0.3)
    before = wait_still(probe)
    boot_before = values(probe.status("robot"))["boot_id"]
    assert probe.call("reset_board").success
    status = probe.wait_status("robot", lambda s: "board reset" in s.message and s.level == b"\x01", 8)
    assert values(status)["board resets"] == "1" and values(status)["state"] == "disarmed"
    assert values(status)["boot_id"] != boot_before
    assert boot_before in values(status)["last reset"]
    arm(probe)
    t = time.monotonic()
    after = probe.wait_message("odom", after=t, timeout_s=5)
    # The pose carries on from where it was (the SDK re-anchors the new boot's counts).
    p0, p1 = before.pose.pose.position, after.pose.pose.position
    assert math.hypot(p1.x - p0.x, p1.y - p0.y) < 0.005
    drive_until_moving(bridge)
    if not case.lockstep:
        assert probe.wait_status("robot", lambda s: s.level == b"\x00", 4)


def test_a_reset_while_moving_grows_the_odom_pose_covariance(bridge: Bridge) -> None:
    """The counts of the reboot are lost; the pose says how much that may cost, and so does odom."""
    probe = bridge.probe
    arm(probe)
    drive_until_moving(bridge)
    before = probe.wait_message("odom", after=time.monotonic()).pose.covariance
    probe.drive(0.2, 0.0, 0.3)
    assert probe.call("reset_board").success  # within cmd_vel_timeout of the last twist: moving
    probe.wait_status("robot", lambda s: "board reset" in s.message, 8)
    arm(probe)  # a lockstep robot's odom comes with commands only
    t = time.monotonic()
    probe.drive(0.0, 0.0, 0.2)
    after = probe.wait_message("odom", after=t, timeout_s=5).pose.covariance
    # 0.2 m/s for a bootloader's 1.5 s or so: about 0.3 m of position uncertainty, 0.09 m^2
    assert after[0] > before[0] + 0.02 and after[7] > before[7] + 0.02
    assert after[35] >= before[35] and after[14] == before[14]  # z does not grow


def test_arm_and_disarm_services(bridge: Bridge) -> None:
    probe = bridge.probe
    arm(probe)
    answer = probe.call("disarm")
    assert answer.success and answer.message == "disarmed"
    probe.wait_status("robot", lambda s: values(s)["state"] == "disarmed")
    truth0 = wait_truth_still(probe)  # the safe state may ramp down
    refused = int(values(probe.status("robot"))["cmd_vel refused"])
    probe.drive(0.3, 0.0, 0.5)
    truth1 = probe.wait_message("truth", after=time.monotonic())
    assert truth1.pose.pose.position.x == pytest.approx(truth0.pose.pose.position.x, abs=1e-3)
    status = probe.wait_status("robot", lambda s: int(values(s)["cmd_vel refused"]) > refused)
    assert "~/disarm" in values(status)["last refusal"]
    arm(probe)
    probe.wait_status("robot", lambda s: values(s)["state"] == "armed")
    drive_until_moving(bridge)


def test_parameters_file_is_applied(bridge: Bridge) -> None:
    import yaml

    expected = yaml.safe_load(PARAMS_YAML.read_text())["/**/roverlink"]["ros__parameters"]
    client = bridge.probe.node.create_client(GetParameters, "roverlink/get_parameters")
    bridge.probe.clients["get_parameters"] = client
    names = sorted(expected)
    answer = bridge.probe.call("get_parameters", GetParameters.Request(names=names))
    got = {}
    for name, value in zip(names, answer.values, strict=True):
        got[name] = next(
            getattr(value, f)
            for f in ("bool_value", "integer_value", "double_value", "string_value", "double_array_value")
            if _field_is(value, f)
        )
    for name in names:
        want = expected[name]
        if name == "url":
            assert got[name].startswith("emu://")  # the command line's --url wins over the file
        elif name == "profile":
            assert got[name] == bridge.case.profile  # and so does --profile
        elif isinstance(want, list):
            assert list(got[name]) == pytest.approx(want)
        else:
            assert got[name] == want, name


def _field_is(value: Any, field: str) -> bool:
    kinds = {"bool_value": 1, "integer_value": 2, "double_value": 3, "string_value": 4, "double_array_value": 8}
    return bool(value.type == kinds[field])


def test_lights_topic_state_and_service(bridge: Bridge) -> None:
    """~/lights sets the turn signals (SET_LIGHTS), ~/lights/state and ~/get_lights report them;
    a robot without TURN_SIGNALS says so."""
    probe = bridge.probe
    latched = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    probe.subscribe("lights_state", String, "roverlink/lights/state", latched)
    probe.clients["get_lights"] = probe.node.create_client(Trigger, "roverlink/get_lights")
    if bridge.case.profile != "diffdrive-tb6612":  # the one reference robot with turn signals
        answer = probe.call("get_lights")
        assert not answer.success and "TURN_SIGNALS" in answer.message
        return
    first = probe.wait_message("lights_state")
    assert first.data.startswith("auto lit=")  # the power-up mode, published on connection
    command = probe.node.create_publisher(String, "roverlink/lights", 10)

    def send(text: str, expected: str) -> Any:
        """Publish `text` until a state that starts with `expected` comes back (the topic may drop
        the first ones before it matches, and repeats of an earlier command may answer first)."""
        t = time.monotonic()
        msg = String()
        msg.data = text

        def answered() -> Any:
            return next((r.msg for r in probe.since("lights_state", t) if r.msg.data.startswith(expected)), None)

        return wait_until(answered, 10, f"the lights state after {text!r}", step=lambda: command.publish(msg))

    send("manual steady=front_left slow=rear", "manual steady=front_left slow=rear fast=- lit=")
    answer = probe.call("get_lights")
    assert answer.success and answer.message.startswith("manual steady=front_left slow=rear fast=- lit=")
    assert "front_left" in answer.message.split("lit=")[1]  # steady: lit at any instant
    send("off", "off lit=-")
    assert probe.call("get_lights").message == "off lit=-"
    send("auto", "auto lit=")
    assert probe.call("get_lights").message.startswith("auto lit=")


def test_sigint_stops_disarms_and_exits(bridge: Bridge) -> None:
    # Last in the module: it stops the module's bridge.
    probe, proc = bridge.probe, bridge.proc
    arm(probe)
    probe.drive(0.3, 0.0, 0.5)
    sig = signal.SIGTERM if bridge.case.profile == "picar" else signal.SIGINT
    assert proc.stop(sig) == 0
    log = proc.log()
    assert "robot stopped, disarmed and closed" in log
    assert "Traceback" not in log
