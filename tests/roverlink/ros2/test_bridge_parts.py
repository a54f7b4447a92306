"""The bridge's plain-Python parts, without ROS: parameters, conversions, the cmd_vel driver (against
the emulator on its virtual clock), diagnostics levels, the connection's retries, and the command
line when rclpy is missing."""

from __future__ import annotations

import itertools
import math
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from host_sdk import CommandRangeError, FeedbackSample, LinkStatistics, Pose, Robot
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.sensors import ImuSample
from host_sdk.session.types import RobotIdentity
from protocol.generated.constants import FEEDBACK_HZ_DEFAULT
from protocol.generated.enums import Board, Capability, FailsafeReason, FeedbackMode, Status
from protocol.generated.messages import LinkStats
from protocol.robotfile import reference_path
from roverlink.ros2 import convert
from roverlink.ros2.diagnostics import (
    ERROR,
    OK,
    STALE,
    WARN,
    DiagnosticsBuilder,
    Event,
    Snapshot,
    feedback_expected_s,
)
from roverlink.ros2.driver import Driver, RefusalLog, arm_hint, in_ros_words
from roverlink.ros2.params import SPECS, BridgeParams, odom_rate_for

ROOT = Path(__file__).resolve().parents[3]


# -- parameters ------------------------------------------------------------------------------------
def test_default_parameters_are_valid_and_conventional() -> None:
    p = BridgeParams.defaults()
    assert (p.odom_frame, p.base_frame, p.publish_tf, p.auto_arm) == ("odom", "base_link", True, False)
    assert p.cmd_vel_timeout == 0.5 and p.odom_rate == 0 and p.diagnostics_rate == 1.0


def test_odom_rate_zero_is_the_robots_own_feedback_rate(tmp_path: Path) -> None:
    """`--robot FILE` alone runs at the file's rate, a reference profile at its robot's; a rate set
    by the user wins; a board the node knows nothing of gets the spec's default."""
    from host_sdk import RobotDescription

    bts = RobotDescription.load(reference_path("diffdrive-bts7960"))
    tb = RobotDescription.load(reference_path("diffdrive-tb6612"))
    auto = BridgeParams.defaults()
    assert (bts.feedback.rate_hz, tb.feedback.rate_hz) == (100.0, 50.0)
    assert odom_rate_for(auto, bts) == 100 and odom_rate_for(auto, tb) == 50
    assert odom_rate_for(auto, None) == FEEDBACK_HZ_DEFAULT
    assert odom_rate_for(BridgeParams.from_values({"odom_rate": 30}), bts) == 30


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("mode", "fast"),
        ("odom_rate", 2.5),
        ("odom_rate", 500),
        ("odom_rate", -1),
        ("watchdog", float("nan")),
        ("publish_tf", 1),
        ("pose_covariance_diagonal", [0.1] * 5),
        ("twist_covariance_diagonal", [0.1, 0.1, 0.1, 0.1, 0.1, -1.0]),
        ("wheel_joints", "left"),
        ("odom_frame", ""),
        ("no_such_parameter", 1),
        ("imu_orientation_covariance_diagonal", [0.1] * 6),
        ("imu_linear_acceleration_covariance_diagonal", [0.1, 0.1, -0.1]),
        ("tf_from", "ekf"),
    ],
)
def test_bad_parameters_are_refused_by_name(name: str, value: object) -> None:
    with pytest.raises(CommandRangeError, match=re.escape(f"{name}")):
        BridgeParams.defaults(**{name: value})  # type: ignore[arg-type]


def test_integer_values_are_taken_for_floats_as_a_yaml_file_writes_them() -> None:
    p = BridgeParams.defaults(watchdog=1, pose_covariance_diagonal=[1, 1, 1, 1, 1, 1])
    assert p.watchdog == 1.0 and p.pose_covariance_diagonal == (1.0,) * 6


def test_docs_list_every_parameter_with_its_default() -> None:
    text = (ROOT / "docs" / "ros2.md").read_text().split("## Parameters\n", 1)[1].split("\n## ", 1)[0]
    rows = dict(re.findall(r"^\| `(\w+)` \| `([^`]*)` \|", text, re.MULTILINE))
    assert sorted(rows) == sorted(spec.name for spec in SPECS)
    for spec in SPECS:
        default = spec.default
        shown = str(default).lower() if isinstance(default, bool) else str(default)
        assert rows[spec.name] == shown.replace("'", ""), spec.name


def test_example_parameters_file_sets_only_real_parameters() -> None:
    yaml = pytest.importorskip("yaml")
    text = (ROOT / "examples" / "ros2" / "roverlink.yaml").read_text()
    values = yaml.safe_load(text)["/**/roverlink"]
    BridgeParams.from_values(values["ros__parameters"])
    # ... and names every parameter the node takes, set or as a commented line a user can uncomment
    named = set(re.findall(r"^\s*#?\s*([a-z_]+):", text, re.MULTILINE))
    assert [spec.name for spec in SPECS if spec.name not in named] == []


# -- conversions -----------------------------------------------------------------------------------
def sample(
    counts: tuple[int, ...],
    *,
    boot_id: int = 1,
    t_us: int = 0,
    speeds: tuple[float, ...] = (0.0, 0.0),
    steering: float = 0.0,
) -> FeedbackSample:
    return FeedbackSample(
        index=0,
        boot_id=boot_id,
        received_s=0.0,
        host_time_s=0.0,
        mcu_time_us=t_us,
        tick=0,
        status=Status.SESSION,
        failsafe_reason=FailsafeReason.NONE,
        encoder_counts=counts,
        wheel_speeds_m_s=speeds,
        efforts=(0.0,) * len(counts),
        steering_rad=steering,
        ack_seq=0,
        pose=None,
    )


def test_quaternion_and_covariance() -> None:
    assert convert.yaw_quaternion(math.pi / 2) == pytest.approx((0, 0, math.sqrt(0.5), math.sqrt(0.5)))
    cov = convert.covariance([1, 2, 3, 4, 5, 6])
    assert [cov[i * 7] for i in range(6)] == [1, 2, 3, 4, 5, 6] and sum(cov) == 21


def test_pose_covariance_grows_by_the_odometry_uncertainty() -> None:
    diagonal = (0.001, 0.001, 0.001, 0.001, 0.001, 0.01)
    known = Pose(1.0, 2.0, 0.5, 0.3, 0.1, 1000)
    assert convert.pose_covariance(diagonal, known) == convert.covariance(diagonal)
    after_reset = Pose(1.0, 2.0, 0.5, 0.3, 0.1, 1000, gaps=1, position_uncertainty_m=0.3, heading_uncertainty_rad=0.2)
    cov = convert.pose_covariance(diagonal, after_reset)
    assert cov[0] == cov[7] == pytest.approx(0.001 + 0.09)
    assert cov[35] == pytest.approx(0.01 + 0.04)
    assert cov[14] == cov[21] == cov[28] == 0.001 and sum(cov) == pytest.approx(sum(diagonal) + 0.22)


def test_stamp_is_the_sample_time_not_the_read_time() -> None:
    # Sampled 12 ms before it was read, read 3 ms ago: stamped 15 ms before ROS now.
    assert convert.stamp_ns(sample_host_s=10.000, host_now_s=10.015, ros_now_ns=5_000_000_000) == 4_985_000_000


def test_twist_comes_from_the_measured_wheel_speeds() -> None:
    diff = DiffDrive(wheel_radius_m=0.03, track_m=0.2, counts_per_rev=1000)
    assert convert.body_twist(diff, sample((0, 0), speeds=(0.1, 0.3))) == pytest.approx((0.2, 1.0))
    ack = Ackermann(wheelbase_m=0.26, wheel_radius_m=0.03, counts_per_rev=720)
    v, w = convert.body_twist(ack, sample((0,), speeds=(0.5,), steering=0.2))
    assert (v, w) == pytest.approx((0.5, 0.5 * math.tan(0.2) / 0.26))


def test_wheel_angles_carry_on_across_a_board_reset() -> None:
    diff = DiffDrive(wheel_radius_m=0.05, track_m=0.2, counts_per_rev=100)
    joints = convert.JointTracker(diff, ("l", "r"), "s")
    assert joints.update(sample((25, 50), speeds=(0.1, 0.2))).positions == pytest.approx((math.pi / 2, math.pi))
    assert joints.update(sample((50, 100))).positions == pytest.approx((math.pi, 2 * math.pi))
    # A new boot restarts the board's counts near 0: the joints do not jump back.
    after = joints.update(sample((3, 1), boot_id=2))
    assert after.positions == pytest.approx((math.pi, 2 * math.pi))
    assert joints.update(sample((28, 26), boot_id=2)).positions == pytest.approx((1.5 * math.pi, 2.5 * math.pi))
    assert joints.update(sample((0, 0), speeds=(0.1, -0.2))).velocities == pytest.approx((2.0, -4.0))


def test_ackermann_joints_include_the_steering() -> None:
    ack = Ackermann(wheelbase_m=0.26, wheel_radius_m=0.05, counts_per_rev=100)
    joints = convert.JointTracker(ack, ("rear",), "steer")
    joints.update(sample((0,), t_us=0, steering=0.0))
    js = joints.update(sample((10,), t_us=100_000, steering=0.1))
    assert js.names == ("rear", "steer")
    assert js.positions == pytest.approx((2 * math.pi * 0.1, 0.1))
    assert js.velocities[1] == pytest.approx(1.0)  # 0.1 rad in 0.1 s
    with pytest.raises(ValueError, match="wheel_joints"):
        convert.JointTracker(ack, ("a", "b"), "steer")


def _vec() -> SimpleNamespace:
    return SimpleNamespace(x=0.0, y=0.0, z=0.0, w=1.0)


def test_imu_message_from_a_jy901_sample() -> None:
    assert convert.euler_quaternion(0.0, 0.0, 0.7) == pytest.approx(convert.yaw_quaternion(0.7))
    msg = SimpleNamespace(
        header=SimpleNamespace(stamp=SimpleNamespace(), frame_id=""),
        orientation=_vec(),
        orientation_covariance=[0.0] * 9,
        angular_velocity=_vec(),
        angular_velocity_covariance=[0.0] * 9,
        linear_acceleration=_vec(),
        linear_acceleration_covariance=[0.0] * 9,
    )
    sample = ImuSample(
        t=1.0,
        accel=(0.1, 0.2, 9.8),
        gyro=None,
        angle=(0.0, 0.0, math.pi / 2),
        mag=None,
        quaternion=None,
        temperature_c=None,
    )
    covariance = convert.ImuCovariance((0.1, 0.2, 0.3), (0.4, 0.5, 0.6), (0.7, 0.8, 0.9))
    convert.fill_imu(msg, ns=1_500_000_000, frame="imu_link", sample=sample, covariance=covariance)
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec, msg.header.frame_id) == (1, 500_000_000, "imu_link")
    q = msg.orientation
    assert (q.x, q.y, q.z, q.w) == pytest.approx((0, 0, math.sqrt(0.5), math.sqrt(0.5)))  # from the angles
    assert msg.angular_velocity_covariance[0] == -1.0  # the gyro was not sent: "not provided"
    assert msg.orientation_covariance == [0.1, 0, 0, 0, 0.2, 0, 0, 0, 0.3]  # the parameters' diagonals
    assert msg.linear_acceleration.z == 9.8
    assert msg.linear_acceleration_covariance == [0.7, 0, 0, 0, 0.8, 0, 0, 0, 0.9]


def test_imu_covariance_defaults_are_the_jy901_datasheet_figures() -> None:
    from protocol.sensors import DEVICES

    jy901, p = DEVICES["jy901"], BridgeParams.defaults()
    angle, heading = math.radians(jy901.angle_sigma_deg), math.radians(jy901.heading_sigma_deg)  # type: ignore[union-attr]
    assert p.imu_orientation_covariance_diagonal == pytest.approx((angle**2, angle**2, heading**2), rel=0.01)
    gyro = math.radians(jy901.gyro_sigma_dps)  # type: ignore[union-attr]
    assert p.imu_angular_velocity_covariance_diagonal == pytest.approx((gyro**2,) * 3, rel=0.01)
    accel = jy901.accel_sigma_g * 9.80665  # type: ignore[union-attr]
    assert p.imu_linear_acceleration_covariance_diagonal == pytest.approx((accel**2,) * 3, rel=0.01)


def test_laser_scan_from_a_binned_scan() -> None:
    import numpy as np

    from host_sdk.sensors import RegularScan

    scan = RegularScan(
        -math.pi, math.pi / 2, np.array([1.0, np.inf, 2.0, np.nan]), np.zeros(4), 3.0, 0.1, -0.025, 0.12, 12.0
    )
    msg = SimpleNamespace(header=SimpleNamespace(stamp=SimpleNamespace(), frame_id=""))
    convert.fill_laser_scan(msg, ns=3_000_000_000, frame="laser", scan=scan)
    assert msg.angle_max == pytest.approx(math.pi / 2) and msg.time_increment == -0.025 and msg.scan_time == 0.1
    assert msg.ranges[0] == 1.0 and math.isinf(msg.ranges[1]) and math.isnan(msg.ranges[3])
    assert (msg.range_min, msg.range_max, msg.header.frame_id) == (0.12, 12.0, "laser")


# -- the driver, against the emulator on its virtual clock --------------------------------------------
@pytest.fixture
def robot() -> Iterator[Robot]:
    with Robot.connect("emu://diffdrive-tb6612?clock=virtual&seed=3", command_timeout_s=0.5) as r:
        r.arm()
        yield r


def make_driver(robot: Robot, **kw: Any) -> tuple[Driver, list[str]]:
    logged: list[str] = []
    options: dict[str, Any] = {"timeout_s": 0.5, "on_timeout": "stop", "lockstep": False}
    options.update(kw)
    return Driver(robot, RefusalLog(logged.append, logged.append), **options), logged


TICK_S = 0.05
"""The node's timer (STREAM_TICK_S)."""


def run(robot: Robot, driver: Driver, seconds: float, cmd: tuple[float, float] | None = None) -> None:
    """Tick the driver at 20 Hz for `seconds` of virtual time, commanding `cmd` at 20 Hz."""
    end = robot.now() + seconds
    next_cmd = robot.now()
    while robot.now() < end:
        if cmd is not None and robot.now() >= next_cmd:
            driver.command(*cmd, robot.now())
            next_cmd += 0.05
        robot.sleep(TICK_S)
        driver.tick(robot.now())


def targets(robot: Robot) -> tuple[float, ...]:
    return tuple(robot.emulator.truth.firmware.targets_mm_s)


def test_cmd_vel_drives_and_silence_holds_zero_armed(robot: Robot) -> None:
    driver, logged = make_driver(robot)
    run(robot, driver, 1.0, (0.3, 0.0))
    assert targets(robot) == (300, 300)
    run(robot, driver, 0.5 + 0.03)  # the timeout, and one tick
    assert targets(robot) == (0, 0)
    run(robot, driver, 2.0)  # many watchdog periods: the zero hold keeps the session alive
    assert robot.state == "armed" and robot.failsafe is None and not logged


def test_release_lets_the_board_fail_safe(robot: Robot) -> None:
    driver, _ = make_driver(robot, on_timeout="release")
    run(robot, driver, 0.5, (0.3, 0.0))
    run(robot, driver, 0.5 + robot.watchdog_s + 0.05)
    assert robot.failsafe is FailsafeReason.COMM_TIMEOUT
    assert robot.emulator.truth.firmware.failsafe_reason is FailsafeReason.COMM_TIMEOUT


@pytest.mark.parametrize("rate", [100, 50])
def test_lockstep_feedback_comes_every_period_however_late_the_executor(rate: int) -> None:
    """Paced (the node's lockstep connection), the SDK sends the setpoints on the board's tick grid:
    FEEDBACK once a period on the board's clock, whether the driver is called at 20 Hz, not at all
    for 0.4 s (a stalled executor, whose 100 Hz timer sent them before), or idle (the zero hold)."""
    url = "emu://diffdrive-bts7960?clock=virtual&drift_ppm=80"
    with Robot.connect(url, mode="lockstep", feedback_hz=rate, paced=True) as robot:
        robot.arm()
        driver, logged = make_driver(robot, lockstep=True)
        stamps: list[int] = []
        robot.on_feedback(lambda sample: stamps.append(sample.mcu_time_us))
        run(robot, driver, 1.0, (0.2, 0.0))  # 20 Hz cmd_vel and ticks
        driver.command(0.2, 0.0, robot.now())
        robot.sleep(0.4)  # nothing calls the driver
        run(robot, driver, 1.5)  # the command times out: the zero hold takes over without a gap
        assert targets(robot) == (0, 0) and robot.state == "armed" and not logged
        period_us = 1_000_000 // rate
        gaps = [b - a for a, b in itertools.pairwise(stamps[3:])]  # after arming's first samples
        assert max(abs(g - period_us) for g in gaps) < period_us / 10  # the crystal's 80 ppm only
        assert len(stamps) == pytest.approx(2.9 * rate, abs=5)


def test_refused_commands_are_logged_once_per_burst(robot: Robot) -> None:
    driver, logged = make_driver(robot)  # the robot refuses (it was connected without clamp)
    for _ in range(10):
        driver.command(5.0, 0.0, robot.now())  # beyond max_wheel_speed
    assert len(logged) == 1 and "linear_m_s = 5.0" in logged[0]
    assert driver.refusals.total == 10
    driver.command(0.1, 0.0, robot.now())
    assert len(logged) == 2 and logged[1] == "cmd_vel accepted again after 10 refused"
    robot.disarm()
    for _ in range(5):
        driver.command(0.1, 0.0, robot.now())
    assert len(logged) == 3 and "not armed" in logged[2]
    driver.hold_off = "disarmed through ~/disarm"
    driver.command(0.1, 0.0, robot.now())
    assert len(logged) == 4 and "~/disarm" in logged[3]


def test_refusals_name_the_arm_service_not_the_python_api(robot: Robot) -> None:
    logged: list[str] = []
    refusals = RefusalLog(logged.append, logged.append, "/robot1/roverlink/arm")
    driver = Driver(robot, refusals, timeout_s=0.5, on_timeout="stop", lockstep=False)
    robot.disarm()
    driver.command(0.1, 0.0, robot.now())
    hint = "call the /robot1/roverlink/arm service (ros2 service call /robot1/roverlink/arm std_srvs/srv/Trigger)"
    assert len(logged) == 1 and hint in logged[0] and "robot.arm()" not in logged[0], logged
    assert refusals.last == "the robot is not armed: " + hint
    for sdk_words in (
        "the session is re-opening after a reset; call robot.arm() when ready",
        "the robot is in FAILSAFE (COMM_TIMEOUT); call robot.arm() to drive again",
    ):
        assert in_ros_words(sdk_words, "/roverlink/arm").endswith(arm_hint("/roverlink/arm"))


def test_zero_hold_never_arms_a_disarmed_robot() -> None:
    with Robot.connect("emu://diffdrive-tb6612?clock=virtual", auto_rearm=True) as robot:
        driver, _ = make_driver(robot)
        run(robot, driver, 1.0)
        assert robot.state == "disarmed"


# -- diagnostics -----------------------------------------------------------------------------------
IDENTITY = RobotIdentity(
    1, 0x1234, (0, 1, 0), Board.EMULATOR, Capability.DIFF_DRIVE, 7, 0, "Car", 250, FeedbackMode.STREAM, 50, 0.0
)


def snap(t: float, **kw: Any) -> Snapshot:
    base: dict[str, Any] = {"url": "emu://", "connection": "connected", "identity": IDENTITY, "state": "armed"}
    base["host"] = LinkStatistics(frames_ok=100 * int(t), frames_sent=20 * int(t))
    base.update(kw)
    return Snapshot(time_s=t, **base)


def board(**counts: int) -> LinkStats:
    fields = {f.name: 0 for f in LinkStats.FIELDS}
    fields.update(counts)
    return LinkStats(**fields)


def test_link_rates_and_rising_errors() -> None:
    d = DiagnosticsBuilder("roverlink")
    link, robot = d.build(snap(1.0, board=board(frames_ok=10), board_time_s=1.0))
    assert (link.level, robot.level, robot.message) == (OK, OK, "armed")
    link, _ = d.build(snap(2.0, board=board(frames_ok=30, crc_errors=2), board_time_s=2.0))
    v = dict(link.values)
    assert v["host frames received/s"] == "100.0" and v["board frames received/s"] == "20.0"
    assert link.level == WARN and "board crc_errors +2" in link.message
    # Counters that restart (a board reset) are not errors rising.
    link, _ = d.build(snap(3.0, board=board(frames_ok=5), board_time_s=3.0))
    assert link.level == OK
    # A busy host's late paced setpoints are said as such.
    late = LinkStatistics(frames_ok=400, frames_sent=80, paced_late=3)
    link, _ = d.build(snap(4.0, host=late, board=board(frames_ok=25), board_time_s=4.0))
    assert link.level == WARN and "host paced_late +3 (a busy host" in link.message
    assert dict(link.values)["host paced_late"] == "3"


def test_levels_for_failsafe_reset_silence_and_no_connection() -> None:
    d = DiagnosticsBuilder("roverlink")
    _, robot = d.build(snap(1.0, state="failsafe", failsafe=FailsafeReason.ENCODER_FAULT))
    assert robot.level == ERROR and "FAILSAFE (ENCODER_FAULT)" in robot.message
    reset = Event(0.5, "reset", "boot_id 0x00000007 -> 0x00000008")
    _, robot = d.build(snap(2.0, state="disarmed", last_reset=reset, resets=1, rearmed_since_reset=False))
    assert robot.level == WARN and "0x00000008" in robot.message and dict(robot.values)["board resets"] == "1"
    link, _ = d.build(snap(3.0, feedback_age_s=0.8, feedback_expected_s=0.5))
    assert link.level == ERROR and link.message.startswith("no FEEDBACK for 0.8 s")
    link, robot = d.build(snap(4.0, connection="reconnecting", connection_error="port gone", attempts=3, host=None))
    assert link.level == ERROR and "port gone" in link.message and "3 failed attempts" in link.message
    assert (robot.level, robot.message) == (STALE, "no connection")


@pytest.mark.parametrize("state", ["disarmed", "failsafe"])
def test_a_silent_lockstep_robot_out_of_armed_is_an_error_as_in_stream_mode(state: str) -> None:
    """A lockstep board streams FEEDBACK whenever it is not armed: its silence is a cut cable or a hang."""
    due = feedback_expected_s(state, lockstep=True, commanding=False, odom_rate=50.0)
    assert due == feedback_expected_s(state, lockstep=False, commanding=False, odom_rate=50.0) == 0.5
    link, _ = DiagnosticsBuilder("roverlink").build(snap(1.0, state=state, feedback_age_s=0.8, feedback_expected_s=due))
    assert link.level == ERROR and link.message.startswith("no FEEDBACK for 0.8 s")
    # Armed, a lockstep board answers commands only: due while the node commands it, not otherwise.
    assert feedback_expected_s("armed", lockstep=True, commanding=True, odom_rate=50.0) == 0.5
    assert feedback_expected_s("armed", lockstep=True, commanding=False, odom_rate=50.0) is None
    assert feedback_expected_s("connecting", lockstep=False, commanding=True, odom_rate=50.0) is None


# -- the command -----------------------------------------------------------------------------------
def test_command_without_rclpy_says_how_to_install(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from roverlink import cli
    from roverlink.commands import ros2

    monkeypatch.setattr(ros2, "missing_modules", lambda: ["rclpy"])
    assert cli.main(["ros2", "--url", "emu://"]) == 2
    err = capsys.readouterr().err
    assert "cannot import rclpy" in err and "pip install 'roverlink[ros2]'" in err and "/opt/ros/jazzy" in err


def test_console_script_takes_the_same_arguments_as_the_command(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """`roverlink.commands.ros2:main` (for `ros2 run`) parses the command's own arguments."""
    from roverlink.commands import ros2

    seen: list[Any] = []
    monkeypatch.setattr(ros2, "cmd_ros2", lambda args: seen.append(args) or 0)
    assert ros2.main(["--url", "emu://", "--profile", "picar", "--ros-args", "-p", "publish_tf:=false"]) == 0
    assert (seen[0].url, seen[0].profile, seen[0].ros_args) == ("emu://", "picar", ["-p", "publish_tf:=false"])
    with pytest.raises(SystemExit):
        ros2.main(["--profile", "no-such-robot"])
    assert "roverlink ros2: error" in capsys.readouterr().err


def test_the_sdk_and_other_commands_never_import_ros() -> None:
    code = (
        "import sys, host_sdk, roverlink.cli;"
        "roverlink.cli.build_parser();"
        "import roverlink.ros2.params, roverlink.ros2.driver, roverlink.ros2.diagnostics, roverlink.ros2.convert;"
        "import roverlink.ros2.frames, roverlink.ros2.urdf;"
        "bad = sorted(m for m in sys.modules if m.split('.')[0] in ('rclpy', 'geometry_msgs', 'nav_msgs'));"
        "assert not bad, bad"
    )
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)
