"""Robot.connect(url, robot=FILE): kinematics from the file, the board compared with it, its
limits, gains and calibration applied (docs/robot-file.md, "Connecting with a robot file")."""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

import pytest

from host_sdk import ArgumentError, Robot, RobotDescription, RobotFileError, RobotMismatchError
from host_sdk.robot.file_check import compare
from protocol.generated.enums import Board
from protocol.robotfile import REFERENCES, reference_path

TB6612 = "emu://diffdrive-tb6612?clock=virtual"


def robot_file(tmp_path: Path, source: str, *edits: tuple[str, str]) -> Path:
    """A copy of reference robot `source` with each (old, new) text replaced once."""
    text = reference_path(source).read_text(encoding="utf-8")
    for old, new in edits:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    path = tmp_path / "my.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("name", REFERENCES)
def test_a_reference_file_connects_to_its_board(name: str) -> None:
    description = RobotDescription.load(reference_path(name))
    with Robot.connect(f"emu://{name}?clock=virtual", robot=reference_path(name)) as robot:
        assert robot.mismatches == ()
        assert robot.kinematics == description.kinematics()
        assert robot.config == description.config()


def test_a_wheel_diameter_unlike_the_boards_is_an_error_naming_both(tmp_path: Path) -> None:
    path = robot_file(tmp_path, "diffdrive-tb6612", ("\nwheel_diameter_m = 0.064", "\nwheel_diameter_m = 0.065"))
    with pytest.raises(RobotMismatchError) as caught:
        Robot.connect(TB6612, robot=path)
    text = str(caught.value)
    assert f"{path}: geometry.wheel_diameter_m = 0.065 m but the board on {TB6612}" in text
    assert "wheel_diameter_um = 64000 (0.064 m)" in text
    assert f"roverlink firmware build --robot {path}" in text
    assert [m.key for m in caught.value.mismatches] == ["geometry.wheel_diameter_m"]


def test_a_file_of_another_drive_lists_every_difference() -> None:
    with pytest.raises(RobotMismatchError) as caught:
        Robot.connect(TB6612, robot=reference_path("picar"))
    found = {m.key: m for m in caught.value.mismatches}
    assert found["drive.kind"].file_value == '"ackermann" (1 wheel)'
    assert found["drive.kind"].board_value == "DIFF_DRIVE (2 wheels)"
    assert found["name"].board_value == '"DiffDriveTB6612"'
    assert found["encoders.counts_per_rev"].file_value == "720"
    assert found["encoders.counts_per_rev"].board_value == "1560"


def test_a_file_for_another_board_is_named() -> None:
    description = RobotDescription.load(reference_path("diffdrive-tb6612"))  # a Mega 2560 robot
    with Robot.connect(TB6612, robot=description) as robot:
        identity, config = robot.identity, robot.config
    on_uno = dataclasses.replace(identity, board=Board.UNO)
    [mismatch] = compare(description, on_uno, config, "/dev/ttyACM0")
    assert str(mismatch).endswith('board = "mega2560" but the board on /dev/ttyACM0 has board = UNO')
    # The emulator stands in for any board.
    assert compare(description, identity, config, TB6612) == []


def test_allow_mismatch_connects_and_keeps_the_mismatch(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    path = robot_file(tmp_path, "diffdrive-tb6612", ("\nwheel_diameter_m = 0.064", "\nwheel_diameter_m = 0.065"))
    with (
        caplog.at_level(logging.WARNING, logger="host_sdk"),
        Robot.connect(TB6612, robot=path, allow_mismatch=True) as robot,
    ):
        assert [m.field for m in robot.mismatches] == ["wheel_diameter_um"]
        assert robot.kinematics == RobotDescription.load(path).kinematics()  # the file's, as asked
    assert "geometry.wheel_diameter_m = 0.065 m" in caplog.text


def test_the_files_limits_and_gains_are_set_at_connect(tmp_path: Path) -> None:
    path = robot_file(
        tmp_path,
        "diffdrive-tb6612",
        ("max_wheel_speed_m_s = 0.6", "max_wheel_speed_m_s = 0.45"),
        ("accel_m_s2 = 1.0", "accel_m_s2 = 0.8"),
        ('safe_state = "brake"', 'safe_state = "coast"'),
        ("kp = 1.0", "kp = 0.7"),
        ("ki = 6.0", "ki = 5.5"),
        ("ks = 70.0", "ks = 55.0"),
    )
    with Robot.connect(TB6612, robot=path) as robot:
        config = robot.read_config()
        assert config == RobotDescription.load(path).config()
        assert config.max_wheel_speed_mm_s == 450 and config.accel_limit_mm_s2 == 800
        for wheel in (0, 1):
            gains = robot.pid(wheel)
            assert (gains.kp, gains.ki, gains.kd, gains.kf, gains.ks) == (0.7, 5.5, 0.0, 1.25, 55.0)  # as the file says
        assert robot.mismatches == ()


def test_the_files_calibration_is_set_on_a_board_with_the_nominal_values(tmp_path: Path) -> None:
    path = robot_file(tmp_path, "diffdrive-tb6612", ("# wheel_diameter_m = ...", "wheel_diameter_m = 0.0655"))
    with Robot.connect(TB6612, robot=path) as robot:
        assert robot.read_config().wheel_diameter_um == 65_500
        assert robot.kinematics is not None and robot.kinematics.wheel_radius_m == pytest.approx(0.03275)


def test_bad_robot_arguments(tmp_path: Path) -> None:
    with pytest.raises(ArgumentError, match="robot"):
        Robot.connect(TB6612, robot=3)  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match="without profile"):
        Robot.connect(TB6612, robot=reference_path("picar"), profile="picar")
    with pytest.raises(ArgumentError, match="allow_mismatch"):
        Robot.connect(TB6612, allow_mismatch=1)  # type: ignore[arg-type]
    with pytest.raises(RobotFileError, match="no such file"):
        Robot.connect(TB6612, robot=tmp_path / "missing.toml")
