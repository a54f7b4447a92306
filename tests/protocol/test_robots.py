"""Reference robots: validated against the spec, and one source for firmware, emulator and SDK."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from protocol.generated.profiles import PROFILES
from protocol.generator import generate, loader, robots

ROOT = generate.ROOT
TEXT = (generate.SPEC.parent / "robots.toml").read_text(encoding="utf-8")
SPEC = loader.load(generate.SPEC, ROOT)


def parse(text: str) -> tuple[robots.Robot, ...]:
    return robots.parse(text, "protocol/spec/robots.toml", SPEC)


def test_three_reference_robots_with_the_design_parameters() -> None:
    assert set(PROFILES) == {"diffdrive-tb6612", "diffdrive-bts7960", "picar"}
    car = PROFILES["diffdrive-tb6612"]
    assert car.wheel_diameter_m == 0.064 and car.encoder_cpr == 1560
    assert PROFILES["diffdrive-bts7960"].feedback_mode.name == "LOCKSTEP"
    picar = PROFILES["picar"]
    assert (picar.config.steering_min_cdeg, picar.config.steering_center_cdeg, picar.config.steering_max_cdeg) == (
        6500,
        9000,
        12500,
    )
    for p in PROFILES.values():
        p.config.pack()  # every default is inside the spec's ranges
        p.pid.pack()


@pytest.mark.parametrize(
    ("old", "new", "problem"),
    [
        (
            "encoder_cpr = 1560",
            "encoder_cpr = 0",
            "robots[0] diffdrive-tb6612.config.encoder_cpr: 0 is outside 1..65535",
        ),
        ('safe_state = "BRAKE"', 'safe_state = "SKID"', "is not a SafeState"),
        ("kp = 1.0", "kp = -1.0", "pid.kp: -1.0 is outside 0..1000"),
        ("feedback_hz = 50\n", "", "missing: feedback_hz"),
        ('board = "MEGA2560"', 'board = "TEENSY"', "board 'TEENSY' is not one of"),
        ('kinematics = "diff"', 'kinematics = "tank"', "kinematics must be one of"),
    ],
)
def test_bad_robot_entries_are_refused(old: str, new: str, problem: str) -> None:
    with pytest.raises(loader.SpecError) as info:
        parse(TEXT.replace(old, new, 1))
    assert problem in str(info.value)
    assert str(info.value).startswith("protocol/spec/robots.toml: ")


@pytest.mark.parametrize("example", sorted(p.example for p in PROFILES.values()))
def test_firmware_profile_header_compiles(example: str, tmp_path: Path) -> None:
    src = tmp_path / "check.cpp"
    src.write_text(
        '#include "robot_profile.h"\n'
        "int main() { return robot_profile::default_config().encoder_cpr > 0 && "
        "robot_profile::default_pid().kp >= 0.0f ? 0 : 1; }\n"
    )
    cmd = ["g++", "-std=c++11", "-Wall", "-Wextra", "-Werror", "-fsyntax-only"]
    cmd += [f"-I{ROOT / 'arduino/RoverLink/src'}", f"-I{ROOT / 'arduino/RoverLink/examples' / example}", str(src)]
    result = subprocess.run(cmd, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr
