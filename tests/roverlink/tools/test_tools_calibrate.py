"""`roverlink calibrate`: the arithmetic, and on the emulator a board whose configuration is wrong
brought within 1 % of ground truth over a 2 m drive and a full turn, on every profile."""

from __future__ import annotations

import io
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from host_sdk import FeedbackSample, Robot
from host_sdk.calibration import load_kinematics
from host_sdk.odometry import Odometry
from roverlink.calibration import (
    Calibration,
    EmulatorObserver,
    ImuObserver,
    PersonObserver,
    measure_turn,
)
from roverlink.calibration import geometry as g
from roverlink.cli import main
from roverlink.emulated import first_collision
from roverlink.interactive import ConsolePrompter
from roverlink.sensors import SensorChoice, open_sensors

PROFILES = ["diffdrive-tb6612", "diffdrive-bts7960", "picar"]


def test_direction_bits() -> None:
    # Forward and counting up: nothing to fix.
    assert g.direction_bits(0, 0, 0, True, 100) == (0, 0)
    # Forward but counting down: the encoder is mirrored.
    assert g.direction_bits(0, 0, 1, True, -100) == (0, 2)
    # Backward and counting down: the motor is mirrored, the encoder is right.
    assert g.direction_bits(2, 0, 1, False, -100) == (0, 0)
    # Backward and counting up: both.
    assert g.direction_bits(0, 1, 0, False, 100) == (1, 0)


def test_arc_through_known_circles() -> None:
    r = 1.5
    for angle in (0.3, 1.0, 2.5, 4.0):
        x, y = r * math.sin(angle), r * (1 - math.cos(angle))
        arc, kappa = g.arc_through(x, y)
        assert kappa == pytest.approx(1 / r)
        assert arc == pytest.approx(r * angle)
        arc, kappa = g.arc_through(x, -y)
        assert kappa == pytest.approx(-1 / r)
    assert g.arc_through(2.0, 0.0) == (2.0, 0.0)


def test_steering_from_circles_and_servo_span() -> None:
    wheelbase, step, ratio, trim = 0.26, 15.0, 0.9, 2.0
    kappas = [math.tan(math.radians(ratio * (s * step - trim))) / wheelbase for s in (1, -1)]
    assert g.steering_from_circles(*kappas, wheelbase, step) == pytest.approx((ratio, trim))
    lo, hi = g.servo_span_for(500, 2500, 9000, 0.9)
    assert (hi - lo) == pytest.approx(2000 / 0.9, abs=1)
    assert lo + 9000 * (hi - lo) / 18000 == pytest.approx(1500, abs=1)  # the centre's pulse stays


def test_other_rules() -> None:
    assert g.counts_per_rev(7855, 4.706) == 1669
    assert g.scaled(64000, 2.0, 1.9) == pytest.approx(60800)
    assert g.track_width(0.2, 2 * math.pi * 1.04, 2 * math.pi) == pytest.approx(0.208)
    with pytest.raises(ValueError, match="turned forward"):
        g.counts_per_rev(100, -1.0)


def _drive_and_compare(robot: Robot, kinematics: object, ackermann: bool) -> tuple[float, float]:
    """Drive 2 m straight, then one full turn, with odometry from the calibrated kinematics;
    relative errors against the emulator's ground truth (position, heading)."""
    odometry = Odometry(kinematics)  # type: ignore[arg-type]

    def integrate(s: FeedbackSample) -> None:
        odometry.update(s.encoder_counts, s.mcu_time_us, s.steering_rad)

    robot.on_feedback(integrate)
    config = robot.config
    speed = config.max_wheel_speed_mm_s / 1000 * 0.25
    robot.arm()
    robot.wait_feedback()
    odometry.reset()
    start = robot.emulator.truth.plant
    while odometry.pose.x_m < 2.0:
        robot.drive_ackermann(speed, 0.0) if ackermann else robot.set_wheel_speeds(speed, speed)
        robot.wait_feedback()
    for _ in range(50):
        robot.stop()
        robot.wait_feedback()
    end = robot.emulator.truth.plant
    truth = math.hypot(end.x_m - start.x_m, end.y_m - start.y_m)
    pose = odometry.pose
    position_error = math.hypot(pose.x_m, pose.y_m) - truth
    odometry.reset()
    theta0 = end.theta_rad
    step = math.radians(config.steering_step_cdeg / 100)
    while odometry.pose.theta_rad < 2 * math.pi:
        if ackermann:
            robot.drive_ackermann(speed * 0.8, step)
        else:
            robot.set_wheel_speeds(-speed * 0.6, speed * 0.6)
        robot.wait_feedback()
    for _ in range(50):
        robot.stop()
        robot.wait_feedback()
    turned = robot.emulator.truth.plant.theta_rad - theta0
    return abs(position_error) / truth, abs(odometry.pose.theta_rad - turned) / turned


@pytest.mark.parametrize("profile", PROFILES)
def test_calibration_brings_odometry_within_one_percent(profile: str) -> None:
    url = f"emu://{profile}?clock=virtual&physical=miscalibrated&seed=2"
    with Robot.connect(url) as robot:
        robot_cfg = robot.emulator.profile.robot.config
        cal = Calibration(robot, EmulatorObserver(robot), say=lambda _t: None)
        result = cal.run()
        after = result.config_after
        # The board now holds the robot's true numbers.
        assert after.encoder_invert == robot_cfg.encoder_invert ^ 1
        assert after.encoder_cpr == pytest.approx(robot_cfg.encoder_cpr * 1.07, abs=1)
        assert after.wheel_diameter_um == pytest.approx(robot_cfg.wheel_diameter_um * 0.95, rel=0.003)
        ackermann = profile == "picar"
        if ackermann:
            assert after.steering_center_cdeg == pytest.approx(9300, abs=25)
        else:
            assert result.track_after_m == pytest.approx(robot.emulator.profile.track_m, rel=0.003)
        position, heading = _drive_and_compare(robot, result.kinematics(), ackermann)
        print(f"{profile}: 2 m drive {position * 100:.2f} %, full turn {heading * 100:.2f} %")
        assert position < 0.01
        assert heading < 0.01


def test_uncalibrated_odometry_is_far_off() -> None:
    """The same check fails on the miscalibrated board with its encoder direction fixed only:
    the test above would catch a calibration that did nothing."""
    with Robot.connect("emu://diffdrive-tb6612?clock=virtual&physical=miscalibrated") as robot:
        robot.set_config(encoder_invert=robot.config.encoder_invert ^ 1)
        position, heading = _drive_and_compare(robot, robot.kinematics, False)
        assert position > 0.04 and heading > 0.04


def test_steering_linkage_ratio_is_measured() -> None:
    with Robot.connect("emu://picar?clock=virtual&steering_ratio=0.95&steering_trim_deg=-2") as robot:
        result = Calibration(robot, EmulatorObserver(robot), say=lambda _t: None).run()
        c = result.config_after
        assert 2000 / (c.servo_max_us - c.servo_min_us) == pytest.approx(0.95, rel=0.02)
        assert c.steering_center_cdeg == pytest.approx(8800, abs=40)


def test_person_observer_asks_and_parses() -> None:
    answers = io.StringIO("y\n9.5\n1.95\n-0.02\n355\n")
    person = PersonObserver(ConsolePrompter(out=io.StringIO(), inp=answers))
    assert person.turned_forward(0) is True
    assert person.revolutions(1) == 9.5
    assert person.displacement() == (1.95, -0.02)
    assert person.rotation_deg() == 355


def test_calibrate_command(tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "cal.json"
    # The URL attaches a JY901: its yaw measures the turns (the emulator's truth the rest).
    url = "emu://diffdrive-bts7960?clock=virtual&physical=miscalibrated&imu=jy901"
    assert main(["calibrate", url, "--yes", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "encoder_invert fixed" in text and "saved to EEPROM" in text and "full turn" in text
    assert "deg by the IMU's yaw (its gyro:" in text and re.search(r"full turn: odometry [\d.]+ deg, by the IMU", text)
    kin = load_kinematics(out)
    assert kin.track_m == pytest.approx(0.26, rel=0.005)  # type: ignore[union-attr]
    # How to use the file: every command takes it, and the SDK.
    assert f"--kinematics {out}" in text and "load_kinematics(" in text
    assert main(["info", url, "--kinematics", str(out)]) == 0
    info = capsys.readouterr()
    assert f"kinematics DiffDrive (from {out}): " in info.out and f"track_m {kin.track_m:g}" in info.out  # type: ignore[union-attr]
    assert "note:" in info.err  # a fresh emulator: the board's configuration is not the calibrated one
    # Declined, measured without the IMU: the board's configuration is put back.
    monkeypatch.setattr("sys.stdin", io.StringIO("n\n"))
    assert main(["calibrate", url, "--no-imu", "--no-check", "-o", str(tmp_path / "no.json")]) == 0
    text = capsys.readouterr().out
    assert "put back" in text and "deg measured: track" in text and "IMU" not in text
    assert not (tmp_path / "no.json").exists()


class _NoProtractor(EmulatorObserver):
    """The emulator's tape measure without its protractor: the IMU has to measure the turns."""

    def rotation_deg(self) -> float:
        raise AssertionError("the IMU measures the turns")


def test_imu_calibration_brings_odometry_within_one_percent() -> None:
    """The miscalibrated board (track 4 % wider than configured), the track measured by the JY901's
    yaw (9-axis: the compass holds it at rest; uncalibrated, so its hard iron costs a little)."""
    url = "emu://diffdrive-tb6612?clock=virtual&physical=miscalibrated&imu=jy901&seed=2"
    with Robot.connect(url) as robot, open_sensors(SensorChoice(imu=robot.transport.endpoints["imu"])) as sensors:
        observer = ImuObserver(_NoProtractor(robot), robot, sensors)
        result = Calibration(robot, observer, say=lambda _t: None, tick=sensors.poll).run()
        assert result.track_after_m == pytest.approx(robot.emulator.profile.track_m, rel=0.005)  # the true track
        assert observer.last is not None and observer.last.disagreement < 0.01
        assert any("by the IMU's yaw" in f for f in result.findings)
        position, heading = _drive_and_compare(robot, result.kinematics(), False)
        print(f"IMU: 2 m drive {position * 100:.2f} %, full turn {heading * 100:.2f} %")
        assert position < 0.01
        assert heading < 0.01


def test_imu_gyro_bias_is_taken_out() -> None:
    """A module in 6-axis mode (no compass: its yaw drifts with the gyro's bias) with a bad bias of
    1 deg/s: the drift measured at rest comes out, which the turn alone would be 3 % off without."""
    url = "emu://diffdrive-tb6612?clock=virtual&track_scale=1.04&imu=jy901&seed=3"
    with Robot.connect(url) as robot, open_sensors(SensorChoice(imu=robot.transport.endpoints["imu"])) as sensors:
        assert sensors.imu is not None
        sensors.imu.configure(six_axis=True)
        robot.emulator.sensors.devices["imu"].model.gyro_bias[2] = 1.0
        observer = ImuObserver(_NoProtractor(robot), robot, sensors)
        cal = Calibration(robot, observer, say=lambda _t: None, tick=sensors.poll)
        cal.track()
        turn = observer.last
        assert turn is not None
        assert math.degrees(turn.drift_rad_s) == pytest.approx(1.0, abs=0.05)
        assert turn.drift_rad_s * turn.span_s / turn.yaw_rad > 0.02
        assert cal.track_m == pytest.approx(robot.emulator.profile.track_m, rel=0.003)


def test_measure_turn_from_batched_samples() -> None:
    """A full turn at 200 Hz, read in 20 ms batches (each sample stamped with its batch's
    arrival), the yaw drifting at 0.02 rad/s: the drift and the gyro's bias come out."""
    rate, bias = 200, 0.02
    t = np.arange(0, 12, 1 / rate)
    turning = (t > 2) & (t < 9)
    true_rate = np.where(turning, 2 * np.pi / 7, 0.0)
    true_yaw = np.cumsum(true_rate) / rate
    batched = np.ceil(t / 0.02) * 0.02
    turn = measure_turn(batched, true_yaw + bias * t, true_rate + bias, (1.0, 2.0), (11.0, 12.0))
    assert turn.yaw_rad == pytest.approx(true_yaw[-1], abs=1e-3)  # 0.06 degree
    assert turn.gyro_rad == pytest.approx(true_yaw[-1], rel=3e-3)
    assert (turn.drift_rad_s, turn.bias_rad_s) == pytest.approx((bias, bias), rel=1e-2)
    with pytest.raises(ValueError, match="samples at rest"):
        measure_turn(batched, true_yaw, true_rate, (20.0, 21.0), (11.0, 12.0))


def test_kinematics_files_are_checked(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"format": "roverlink-calibration/1", "kinematics": {"type": "diff", "track_m": -1}}))
    with pytest.raises(SystemExit) as exit_info:
        main(["monitor", "emu://", "--kinematics", str(bad)])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert f"argument --kinematics: {bad}:" in err
    with pytest.raises(SystemExit):
        main(["teleop", "emu://", "--kinematics", str(tmp_path / "missing.json")])
    assert "missing.json: No such file" in capsys.readouterr().err


def test_an_imu_alone_gets_an_open_floor_and_a_collision_is_named(tmp_path: Path) -> None:
    # An IMU needs no surroundings: the robot is on an open floor, with room for the 2 m drive.
    with Robot.connect("emu://diffdrive-tb6612?clock=virtual&imu=jy901") as robot:
        assert robot.emulator.sensors.world.scene.name == "empty"
    wall = tmp_path / "wall.toml"
    wall.write_text("[[walls]]\nfrom = [0.4, -1.0]\nto = [0.4, 1.0]\n", encoding="utf-8")
    with Robot.connect(f"emu://diffdrive-tb6612?clock=virtual&imu=jy901&world={wall}") as robot:
        assert first_collision(robot) is None
        robot.arm()
        for _ in range(50):  # 1 s: into the wall 0.4 m ahead
            robot.drive(0.3, 0.0)
            robot.wait_feedback()
        hit = first_collision(robot)
    assert hit is not None and hit.startswith("walls[0] at (0.40, ")
