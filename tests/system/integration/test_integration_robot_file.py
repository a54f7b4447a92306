"""The SDK on the emulated robot a robot file describes: `emu://?robot=PATH` in process and
`roverlink emulate --robot FILE` over a pty. The file's geometry is unlike every reference robot's,
so odometry is right only when both the plant and the SDK take it from the file."""

from __future__ import annotations

import io
import sys
from pathlib import Path

import pytest

from host_sdk import Robot, RobotDescription, kinematics_for
from host_sdk.errors import CommandRangeError
from host_sdk.kinematics import Ackermann, DiffDrive
from roverlink.cli import main
from roverlink.commands.demo import DemoResult, drive_square
from tests.support.emulate import emulate


def robot_file(tmp_path: Path, reference: str, *changes: tuple[str, str]) -> Path:
    """`roverlink robot new --from reference`, then each (old, new) text replaced."""
    path = tmp_path / f"my-{reference}.toml"
    assert main(["robot", "new", str(path), "--from", reference]) == 0
    text = path.read_text(encoding="utf-8")
    for old, new in changes:
        assert old in text, old
        text = text.replace(old, new)
    path.write_text(text, encoding="utf-8")
    assert main(["robot", "check", str(path)]) == 0
    return path


WIDE = (('name = "diffdrive-tb6612"', 'name = "wide-one"'), ("track_m = 0.2 ", "track_m = 0.32 "))
WIDE += (("wheel_diameter_m = 0.064", "wheel_diameter_m = 0.08"),)
LONG = (("wheelbase_m = 0.26", "wheelbase_m = 0.34"), ("wheel_diameter_m = 0.065", "wheel_diameter_m = 0.08"))


@pytest.fixture
def wide_diffdrive(tmp_path: Path) -> Path:
    """A differential robot with a track and wheels unlike every reference robot's."""
    return robot_file(tmp_path, "diffdrive-tb6612", *WIDE)


@pytest.fixture
def long_car(tmp_path: Path) -> Path:
    """The PiCar with a longer wheelbase and larger wheels."""
    return robot_file(tmp_path, "picar", *LONG)


def square(path: Path, side_m: float, kinematics: DiffDrive | Ackermann | None = None) -> tuple[DemoResult, float]:
    """The SDK drives a square on odometry; (the result, the path length driven in truth)."""
    with Robot.connect(f"emu://?robot={path}&clock=virtual", kinematics=kinematics) as robot:
        assert robot.transport.profile is None
        robot.arm()
        result = drive_square(robot, side_m=side_m, out=io.StringIO())
        emu = robot.emulator
        assert emu is not None
        return result, emu.truth.plant.distance_m


@pytest.mark.parametrize(
    ("fixture", "reference", "side_m"), [("wide_diffdrive", "diffdrive-tb6612", 1.0), ("long_car", "picar", 0.8)]
)
def test_a_square_ends_where_the_truth_is_only_with_the_files_geometry(
    fixture: str, reference: str, side_m: float, request: pytest.FixtureRequest
) -> None:
    path: Path = request.getfixturevalue(fixture)
    with Robot.connect(f"emu://?robot={path}&clock=virtual") as robot:
        assert robot.kinematics == RobotDescription.load(path).kinematics()  # taken from the file
    result, driven = square(path, side_m)
    assert result.position_error_m is not None and result.position_error_m < 0.01 * driven
    wrong, _ = square(path, side_m, kinematics_for(reference))  # the reference robot's geometry
    assert wrong.position_error_m is not None and wrong.position_error_m > 0.03 * driven


@pytest.mark.parametrize("problem", ["missing", "bad key"])
def test_a_bad_robot_file_is_its_error_naming_file_line_and_key(tmp_path: Path, problem: str) -> None:
    path = tmp_path / "missing.toml"
    expected = f"{path}: no such file"
    if problem == "bad key":
        path = robot_file(tmp_path, "picar")
        text = path.read_text(encoding="utf-8").replace("track_m = 0.16", "trak_m = 0.16")
        path.write_text(text, encoding="utf-8")
        line = next(i for i, x in enumerate(text.splitlines(), 1) if x.startswith("trak_m"))
        expected = f"{path}:{line}: geometry.trak_m: unknown key (did you mean 'track_m'?)"
    with pytest.raises(CommandRangeError) as caught:
        Robot.connect(f"emu://?robot={path}&clock=virtual")
    assert expected in str(caught.value)
    assert main(["emulate", "--robot", str(path)]) == 2  # refused before serving anything


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="needs Linux ptys")
def test_roverlink_emulate_serves_the_files_robot(wide_diffdrive: Path) -> None:
    kinematics = RobotDescription.load(wide_diffdrive).kinematics()
    with (
        emulate("--quiet", "--robot", str(wide_diffdrive), clean_exit=True) as board,
        Robot.connect(board.url, kinematics=kinematics) as robot,
    ):
        assert robot.identity.robot_name == "wide-one"  # the file's name
        assert (robot.config.wheel_diameter_um, robot.config.encoder_cpr) == (80000, 1560)
        robot.arm()
        robot.odometry.reset()
        for _ in range(250):  # 5 s of feedback at most
            if robot.odometry.pose.x_m >= 0.1:
                break
            robot.set_wheel_speeds(0.2, 0.2)
            robot.wait_feedback(1.0)
        robot.stop()
        assert robot.odometry.pose.x_m >= 0.1
