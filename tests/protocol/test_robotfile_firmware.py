"""A robot file as the firmware's robot_profile.h (protocol.robotfile.firmware): the reference robots'
files give the examples' headers (only the origin and the reported name differ), a changed file's
values reach the header, and names the firmware cannot report are refused."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from protocol.generated.profiles import PROFILES
from protocol.robotfile import REFERENCES, check, load, reference_path
from protocol.robotfile.firmware import example_for, name_problem, profile_header

ROOT = Path(__file__).resolve().parents[2]
# The lines that say where a header comes from and what the firmware reports as its name.
ORIGIN = re.compile(r"^(// DO NOT EDIT|// Defaults of|// Change them|static const char NAME|// Wiring \(|.*// valid: )")


def _body(text: str) -> list[str]:
    return [line for line in text.splitlines() if not ORIGIN.match(line)]


@pytest.mark.parametrize("name", REFERENCES)
def test_a_reference_file_gives_its_examples_header(name: str) -> None:
    example = PROFILES[name].example
    robot = load(reference_path(name))
    assert example_for(robot) == example
    text = profile_header(robot, example, f"{name}.toml")
    reference = (ROOT / "arduino" / "RoverLink" / "examples" / example / "robot_profile.h").read_text()
    assert _body(text) == _body(reference)
    assert f'static const char NAME[] = "{name}";' in text  # the file's robot name, not the example's
    assert text.startswith(f"// DO NOT EDIT: generated from {name}.toml")


def test_a_changed_file_reaches_the_header(tmp_path: Path) -> None:
    text = reference_path("picar").read_text()
    text = text.replace("wheel_diameter_m = 0.065", "wheel_diameter_m = 0.0712")
    text = text.replace("counts_per_rev = 720", "counts_per_rev = 1000").replace('name = "picar"', 'name = "my car"')
    path = tmp_path / "my.toml"
    path.write_text(text)
    header = profile_header(load(path), "AckermannPiCar", str(path))
    assert 'static const char NAME[] = "my car";' in header
    assert "0x20, 0x16, 0x01, 0x00,  // wheel_diameter_um = 71200" in header
    assert "0xE8, 0x03,  // encoder_cpr = 1000" in header


@pytest.mark.parametrize(
    ("name", "problem"),
    [("x" * 25, "at most 24 characters"), ('say "hi"', "ASCII text"), ("caf\u00e9", "ASCII text")],
)
def test_names_the_firmware_cannot_report(name: str, problem: str) -> None:
    assert problem in name_problem(name)
    assert name_problem("x" * 24) == ""


def test_the_lights_power_up_mode_reaches_the_header(tmp_path: Path) -> None:
    text = reference_path("diffdrive-tb6612").read_text()
    path = tmp_path / "dark.toml"
    path.write_text(text.replace('\nmode = "auto"', '\nmode = "off"'))
    header = profile_header(load(path), "DiffDriveTB6612", str(path))
    assert "LightsMode LIGHTS_MODE = roverlink::proto::LightsMode::OFF;" in header
    reference = profile_header(load(reference_path("diffdrive-tb6612")), "DiffDriveTB6612", "x.toml")
    assert "LightsMode LIGHTS_MODE = roverlink::proto::LightsMode::AUTO;" in reference


def test_a_files_firmware_example_is_its_own_else_the_drives(tmp_path: Path) -> None:
    """`[firmware] example` names the sketch; left out, a reference robot of the same drive and
    driver names it; a name no sketch could have is refused with the key and the value."""
    text = reference_path("diffdrive-tb6612").read_text()
    path = tmp_path / "mine.toml"
    path.write_text(text.replace('example = "DiffDriveTB6612"', 'example = "MyCar"'))
    assert example_for(load(path)) == "MyCar"
    path.write_text(text.replace('example = "DiffDriveTB6612"', 'example = ""'))
    assert example_for(load(path)) == "DiffDriveTB6612"
    path.write_text(text.replace('example = "DiffDriveTB6612"', 'example = "my car"'))
    problems = [str(p) for p in check(path)]
    assert any("firmware.example: = 'my car': an example sketch's name" in p for p in problems), problems
