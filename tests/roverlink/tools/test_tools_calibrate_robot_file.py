"""`roverlink calibrate --robot FILE`: the measured values go into the robot file's [calibration]
(the user's comments kept, nothing unmeasured written), and the next run's odometry, with the
kinematics `RobotDescription.load(FILE).kinematics()` gives, matches the emulator's truth where the
file's nominal values did not."""

from __future__ import annotations

import io
import math
from pathlib import Path

import pytest

from host_sdk import FeedbackSample, Robot, RobotDescription, RobotFileError
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.odometry import Odometry
from protocol.robotfile import load
from roverlink.calibration.robot_file import edited, write_measured
from roverlink.cli import main

COMMENT = "# my robot: measured on the kitchen floor, tyres worn\n"


def _new_file(tmp_path: Path, source: str) -> Path:
    """`roverlink robot new`, with a comment of the user's above [calibration] and one in it."""
    path = tmp_path / "my.toml"
    assert main(["robot", "new", str(path), "--from", source]) == 0
    text = path.read_text(encoding="utf-8")
    text = text.replace("[calibration]\n", f"{COMMENT}[calibration]  # keep\n# my note in the section\n")
    path.write_text(text, encoding="utf-8")
    return path


def _drive(robot: Robot, odometries: list[Odometry], ackermann: bool) -> list[tuple[float, float]]:
    """1 m straight, then a full turn, steered by the first odometry while all integrate the same
    feedback: each one's relative error against the emulator's truth (distance, heading)."""

    def integrate(s: FeedbackSample) -> None:
        for odometry in odometries:
            odometry.update(s.encoder_counts, s.mcu_time_us, s.steering_rad)

    def stop_and_reset() -> list[tuple[float, float]]:
        """Stopped: each odometry's (distance, heading) since its last reset, then reset."""
        for _ in range(50):
            robot.stop()
            robot.wait_feedback()
        ends = [(math.hypot(o.pose.x_m, o.pose.y_m), o.pose.theta_rad) for o in odometries]
        for odometry in odometries:
            odometry.reset()
        return ends

    robot.on_feedback(integrate)
    speed = robot.config.max_wheel_speed_mm_s / 1000 * 0.25
    step = math.radians(robot.config.steering_step_cdeg / 100)
    robot.arm()
    stop_and_reset()
    start = robot.emulator.truth.plant
    while odometries[0].pose.x_m < 1.0:
        robot.drive_ackermann(speed, 0.0) if ackermann else robot.set_wheel_speeds(speed, speed)
        robot.wait_feedback()
    distances = [d for d, _ in stop_and_reset()]
    middle = robot.emulator.truth.plant
    while odometries[0].pose.theta_rad < 2 * math.pi:
        if ackermann:
            robot.drive_ackermann(speed * 0.8, step)
        else:
            robot.set_wheel_speeds(-speed * 0.6, speed * 0.6)
        robot.wait_feedback()
    headings = [h for _, h in stop_and_reset()]
    truth_m = math.hypot(middle.x_m - start.x_m, middle.y_m - start.y_m)
    truth_rad = robot.emulator.truth.plant.theta_rad - middle.theta_rad
    return [
        (abs(d - truth_m) / truth_m, abs(h - truth_rad) / truth_rad) for d, h in zip(distances, headings, strict=True)
    ]


@pytest.mark.parametrize("source", ["diffdrive-tb6612", "picar"])
def test_calibrate_writes_the_robot_file_and_the_next_run_uses_it(
    source: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    path = _new_file(tmp_path, source)
    nominal = RobotDescription.load(path)
    url = f"emu://{source}?clock=virtual&physical=miscalibrated&seed=2"
    assert main(["calibrate", url, "--robot", str(path), "--yes", "--no-check"]) == 0
    out = capsys.readouterr().out
    assert f"measured values written to {path} [calibration]" in out
    # The direction the calibration found is a build fact: written to its own section, with how to rebuild.
    assert "also written to" in out and "  [encoders] invert = [true" in out
    assert f"roverlink firmware flash --robot {path} --port PORT" in out
    assert not (tmp_path / "calibration.json").exists()  # --robot without -o: the robot file only

    text = path.read_text(encoding="utf-8")
    assert COMMENT in text and "[calibration]  # keep\n# my note in the section\n" in text
    found = load(path).encoders.invert
    assert found != nominal.encoders.invert  # the board's fix, now the file's
    assert "  [encoders] invert = [" + ", ".join("true" if f else "false" for f in found) + "]" in out
    assert [line for line in text.splitlines() if line.startswith("invert = ")] == [
        "invert = ["
        + ", ".join("true" if f else "false" for f in found)
        + "]  # Per wheel channel: reverse the count direction."
    ]
    assert main(["robot", "check", str(path)]) == 0
    section = text[text.index("[calibration]") :]
    assert "wheelbase_m" not in section  # calibration does not measure it
    ackermann = source == "picar"
    cal = load(path).calibration
    truth = nominal.config()
    assert cal.counts_per_rev == pytest.approx(truth.encoder_cpr * 1.07, abs=1)
    assert cal.wheel_diameter_m == pytest.approx(nominal.geometry.wheel_diameter_m * 0.95, rel=0.003)
    if ackermann:
        assert cal.steering_trim_deg == pytest.approx(3.0, abs=0.25)
        assert cal.track_m is None and "\ntrack_m" not in section  # measured only on a differential drive
    else:
        assert cal.track_m == pytest.approx(nominal.geometry.track_m * 1.04, rel=0.003)
        assert "steering_trim_deg =" not in section.replace("# steering_trim_deg =", "")

    # The next run: a new connection, its kinematics from the file; the board holds what the
    # calibration saved to EEPROM (a fresh emulator does not: put it there, directions included).
    described = RobotDescription.load(path)
    kinematics = described.kinematics()
    assert isinstance(kinematics, Ackermann if ackermann else DiffDrive)
    with Robot.connect(url, kinematics=kinematics) as robot:
        config = described.config()
        robot.set_config(
            encoder_invert=robot.config.encoder_invert ^ 1,
            encoder_cpr=config.encoder_cpr,
            wheel_diameter_um=config.wheel_diameter_um,
            steering_center_cdeg=config.steering_center_cdeg,
        )
        (cal_m, cal_rad), (nom_m, nom_rad) = _drive(
            robot, [Odometry(robot.kinematics), Odometry(nominal.kinematics())], ackermann
        )
    print(f"{source}: calibrated {cal_m:.2%} / {cal_rad:.2%}, nominal {nom_m:.2%} / {nom_rad:.2%}")
    assert cal_m < 0.01 and cal_rad < 0.015
    assert nom_m > 0.05 and nom_rad > 0.05


def test_declined_or_wrong_file_leaves_the_file_alone(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    path = _new_file(tmp_path, "diffdrive-tb6612")
    before = path.read_text(encoding="utf-8")
    url = "emu://diffdrive-tb6612?clock=virtual&physical=miscalibrated"
    monkeypatch.setattr("sys.stdin", io.StringIO("n\n"))
    assert main(["calibrate", url, "--robot", str(path), "--no-check"]) == 0
    assert path.read_text(encoding="utf-8") == before
    # Another drive's file: refused before anything moves.
    car = tmp_path / "car.toml"
    assert main(["robot", "new", str(car), "--from", "picar"]) == 0
    capsys.readouterr()
    assert main(["calibrate", url, "--robot", str(car), "--yes"]) == 1
    err = capsys.readouterr().err  # refused at connect: the board is compared with the file
    assert f"{car} does not describe the board" in err and "firmware build --robot" in err
    # A file with a problem: its problems, and no connection.
    path.write_text(before.replace("track_m = 0.2", "track_m = -1"), encoding="utf-8")
    with pytest.raises(SystemExit) as ended:  # argparse refuses it, before anything connects
        main(["calibrate", "emu://nosuchrobot", "--robot", str(path), "--yes"])
    assert ended.value.code == 2
    assert f"{path}:31: geometry.track_m: = -1: out of range" in capsys.readouterr().err


def test_edit_keeps_everything_else() -> None:
    text = "name = 'r'\r\n# mine\r\n[calibration]\r\ntrack_m = 0.2  # tape\r\n# note\r\n\r\n[pid]\r\nkp = 1.0"
    out = edited(text, {"track_m": 0.25, "counts_per_rev": 800})
    assert out == (
        "name = 'r'\r\n# mine\r\n[calibration]\r\ntrack_m = 0.25  # tape\r\n# note\r\ncounts_per_rev = 800\r\n"
        "\r\n[pid]\r\nkp = 1.0"
    )
    # No section: one is added at the end.
    assert edited("a = 1", {"track_m": 0.3}) == "a = 1\n\n[calibration]\ntrack_m = 0.3\n"


def test_an_edit_that_would_not_read_back_changes_nothing(tmp_path: Path) -> None:
    path = tmp_path / "my.toml"
    assert main(["robot", "new", str(path), "--from", "diffdrive-tb6612"]) == 0
    # [calibration] given as an inline table: a second [calibration] table would not be TOML.
    text = path.read_text(encoding="utf-8").replace("[calibration]\n", "")
    text = text.replace("[drive]\n", "calibration = { track_m = 0.2 }\n\n[drive]\n")
    path.write_text(text, encoding="utf-8")
    with pytest.raises(RobotFileError, match="not valid TOML"):
        write_measured(path, {"track_m": 0.21})
    assert path.read_text(encoding="utf-8") == text


def test_a_write_that_fails_lists_what_to_set_by_hand(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The file holds [calibration] as an inline table the editor cannot extend: nothing is
    written, and the summary says every measured value and direction to set by hand."""
    monkeypatch.chdir(tmp_path)
    path = _new_file(tmp_path, "diffdrive-tb6612")
    text = path.read_text(encoding="utf-8").replace("[calibration]  # keep\n", "")
    text = text.replace('entropy_pin = "A0"', 'entropy_pin = "A0"\ncalibration = { }')
    path.write_text(text, encoding="utf-8")
    url = "emu://diffdrive-tb6612?clock=virtual&physical=miscalibrated&seed=2"
    assert main(["calibrate", url, "--robot", str(path), "--yes", "--no-check"]) == 1
    out = capsys.readouterr().out
    assert path.read_text(encoding="utf-8") == text
    assert "error: the robot file was not changed" in out
    by_hand = out[out.index("to keep what was measured, set in the robot file:") :]
    assert "  [calibration] wheel_diameter_m = " in by_hand and "counts_per_rev = " in by_hand
    assert "track_m = " in by_hand and "  [encoders] invert = [" in by_hand


def test_a_linkage_too_weak_for_the_boards_pulses_is_said_not_fatal(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Wheels that turn 0.9 degrees per servo degree need servo_min_us 388, below the board's 400:
    the calibration finishes, keeps the span and says what the board's angles are then."""
    monkeypatch.chdir(tmp_path)
    url = "emu://picar?clock=virtual&steering_ratio=0.9"
    assert main(["calibrate", url, "--yes", "--no-check", "-o", "cal.json"]) == 0
    out = capsys.readouterr().out
    assert "steering: 0.900 wheel degrees per servo degree" in out
    assert "servo_min_us = 388 is outside the board's 400..2600 us" in out
    assert "the span is left at 500..2500 us, so the board's steering angles are 1.11x the wheels'" in out
