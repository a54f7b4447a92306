"""`roverlink emulate --backend simavr --robot FILE`: the firmware built from a user's robot file runs
in simavr, reporting the file's robot name and defaults, with the plant the file describes around
it; a file with a problem serves nothing (exit 2)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from emulator.backends.simavr.robotfile import file_profile
from host_sdk import Robot
from protocol.generated.enums import LightsMode
from protocol.generated.messages import SetConfig
from protocol.robotfile import load, reference_path
from tests.support.emulate import emulate


def _my_car(tmp_path: Path, name: str = "my-car") -> Path:
    text = reference_path("picar").read_text()
    text = text.replace('name = "picar"', f'name = "{name}"').replace("wheelbase_m = 0.26", "wheelbase_m = 0.235")
    text = text.replace("wheel_diameter_m = 0.065", "wheel_diameter_m = 0.0712").replace(
        "rate_hz = 50.0", "rate_hz = 40.0"
    )
    path = tmp_path / "my_car.toml"
    path.write_text(text)
    return path


def test_the_files_firmware_serves_the_files_identity_and_config(tmp_path: Path) -> None:
    path = _my_car(tmp_path)
    expected = load(path).config()
    with emulate("--backend", "simavr", "--robot", str(path), "--quiet") as board, Robot.connect(board.url) as robot:
        assert robot.identity.robot_name == "my-car"
        config = robot.read_config()
        for field in SetConfig.FIELDS:
            assert getattr(config, field.name) == getattr(expected, field.name), field.name


def test_the_plant_has_the_files_geometry(tmp_path: Path) -> None:
    profile = file_profile(load(_my_car(tmp_path)), "AckermannPiCar")
    assert profile.wheel_radius_m == 0.0356
    assert profile.robot.wheelbase_m == 0.235
    assert profile.robot.wiring.esc_pin == 9
    assert profile.plant.timing.eeprom_bytes == 1024  # the Uno's


def test_a_file_with_a_problem_serves_nothing(tmp_path: Path) -> None:
    path = _my_car(tmp_path, name="x" * 30)
    result = subprocess.run(
        [sys.executable, "-m", "roverlink", "emulate", "--backend", "simavr", "--robot", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 2
    assert result.stdout == ""  # no port was served
    assert "name" in result.stderr and "at most 24 characters" in result.stderr


def test_the_files_power_up_lights_mode_is_the_builds(tmp_path: Path) -> None:
    """`[lights] mode = "off"` compiled into the firmware: the real firmware in simavr starts its
    session dark, and the file's connect check finds it as the file says."""
    text = reference_path("diffdrive-tb6612").read_text()
    assert text.count('\nmode = "auto"') == 1
    path = tmp_path / "dark.toml"
    path.write_text(text.replace('\nmode = "auto"', '\nmode = "off"'))
    with (
        emulate("--backend", "simavr", "--robot", str(path), "--quiet") as board,
        Robot.connect(board.url, robot=path) as robot,
    ):
        assert robot.mismatches == ()
        state = robot.lights()
        assert state.mode is LightsMode.OFF and int(state.lit) == 0
