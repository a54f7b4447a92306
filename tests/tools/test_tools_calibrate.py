"""`roverlink calibrate`: the arithmetic, and on the emulator a board whose configuration is wrong
brought within 1 % of ground truth over a 2 m drive and a full turn, on every profile."""

from __future__ import annotations

import io
import math
from pathlib import Path

import pytest

from host_sdk import FeedbackSample, Robot
from host_sdk.odometry import Odometry
from roverlink.calibration import Calibration, EmulatorObserver, PersonObserver, load_kinematics
from roverlink.calibration import geometry as g
from roverlink.cli import main
from roverlink.console import ConsolePrompter

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
    url = "emu://diffdrive-bts7960?clock=virtual&physical=miscalibrated"
    assert main(["calibrate", url, "--yes", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "encoder_invert fixed" in text and "saved to EEPROM" in text and "full turn" in text
    kin = load_kinematics(out)
    assert kin.track_m == pytest.approx(0.26, rel=0.003)  # type: ignore[union-attr]
    # Declined: the board's configuration is put back.
    monkeypatch.setattr("sys.stdin", io.StringIO("n\n"))
    assert main(["calibrate", url, "--no-check", "-o", str(tmp_path / "no.json")]) == 0
    assert "put back" in capsys.readouterr().out
    assert not (tmp_path / "no.json").exists()
