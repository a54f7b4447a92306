"""Reference robots: validated against the spec, and one source for firmware, emulator and SDK."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from protocol.generated.profiles import PROFILES
from protocol.generator import generate, hardware, loader, robots

ROOT = generate.ROOT
TEXT = (generate.SPEC.parent / "robots.toml").read_text(encoding="utf-8")
SPEC = loader.load(generate.SPEC, ROOT)
CONTRACT = hardware.load(generate.SPEC.parent / "hardware.toml", ROOT, SPEC)


def parse(text: str) -> tuple[robots.Robot, ...]:
    return robots.parse(text, "protocol/spec/robots.toml", SPEC, CONTRACT)


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
        (
            "{ a = 18, b = 19 }",
            "{ a = 18, b = 99 }",
            "encoders[1].b: 99 is not a pin of the MEGA2560 (0..69 or A0..A15)",
        ),
        ('{ a = "A10", b = "A11" }', '{ a = "A10", b = "A16" }', "'A16' is not a pin of the MEGA2560"),
        ("pwm = 6, in1 = 22", "pwm = 1, in1 = 22", "motors[0].pwm: pin 1 is the serial port's"),
        (
            "in1 = 22, in2 = 23",
            "in1 = 22, in2 = 22",
            "motors[0].in2: pin 22 already serves motors[0].in1",
        ),
        ("leds = { front_left = 30,", "leds = { front_centre = 30,", "one pin per Lights bit: front_left"),
        ("servo = 10\n", "", "wiring.servo: needed exactly when the robot has the STEERING_SERVO capability"),
        ('driver = "TB6612", pwm = 7', 'driver = "DRV8833", pwm = 7', "driver 'DRV8833' is not one of"),
        (
            "encoders = [{ a = 2, b = 3 }, { a = 18, b = 19 }]",
            "encoders = [{ a = 2, b = 3 }]",
            "1 listed, the capabilities ask for 2",
        ),
        (
            "servo = 10\n",
            "servo = 6\n",
            "the ESC and servo pulses need the pins of one 16-bit timer (Timer1: pins 9, 10)",
        ),
        ("pwm = 7, in1 = 24", "pwm = 40, in1 = 24", "motors[1].pwm: pin 40 has no PWM output on the MEGA2560"),
        ("{ a = 18, b = 19 }", "{ a = 40, b = 19 }", "encoders[1].a: pin 40 cannot interrupt on the MEGA2560"),
    ],
)
def test_bad_robot_entries_are_refused(old: str, new: str, problem: str) -> None:
    with pytest.raises(loader.SpecError) as info:
        parse(TEXT.replace(old, new, 1))
    assert problem in str(info.value)
    assert str(info.value).startswith("protocol/spec/robots.toml: ")


@pytest.mark.slow  # a C++ compiler: the fast lane needs none
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


def test_robots_may_share_only_what_the_hardware_shares() -> None:
    """One STBY for both TB6612 channels is fine (the reference car does it), and so is one
    enable pin for R_EN and L_EN of a BTS7960; one pin for two enables of two boards is not."""
    parse(TEXT.replace("r_en = 22, l_en = 23", "r_en = 22, l_en = 22"))
    with pytest.raises(loader.SpecError, match=r"motors\[1\]\.r_en: pin 22 already serves motors\[0\]\.r_en"):
        parse(TEXT.replace("r_en = 24, l_en = 25", "r_en = 22, l_en = 25"))


def test_the_examples_take_every_pin_from_the_generated_profile() -> None:
    """No sketch writes a pin number of its own: they all come from robots.toml."""
    own_pin = re.compile(r"const\s+uint8_t\s+\w+\s*=\s*(?:\d+|A\d+)\s*;|PulseChannel::[ABC]\b")
    for profile in PROFILES.values():
        sketch = ROOT / "arduino/RoverLink/examples" / profile.example / f"{profile.example}.ino"
        text = sketch.read_text(encoding="utf-8")
        assert not own_pin.findall(text), sketch
        header = (sketch.parent / "robot_profile.h").read_text(encoding="utf-8")
        for part in profile.wiring.encoders:
            assert f"= {part.pin('a')};" in header and f"= {part.pin('b')};" in header
