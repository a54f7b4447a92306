"""Reference robots: their robot files, checked as a user's are and as reference robots, the one
source of the firmware examples' headers, the emulator's and the SDK's profiles and docs/robots.md."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from protocol.generated.profiles import PROFILES
from protocol.generator import generate, loader
from protocol.robotfile import load, parse

ROOT = generate.ROOT


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


REFERENCE = ROOT / "protocol" / "robots" / "diffdrive-tb6612.toml"


def _tree(tmp_path: Path, files: dict[str, str]) -> Path:
    """A checkout under `tmp_path`: the spec, and the reference robot folder holding `files`."""
    spec = tmp_path / "protocol" / "spec"
    spec.mkdir(parents=True)
    for name in ("roverlink.toml", "hardware.toml"):
        shutil.copy(generate.SPEC.parent / name, spec / name)
    (tmp_path / "protocol" / "robots").mkdir()
    for name, text in files.items():
        (tmp_path / "protocol" / "robots" / name).write_text(text, encoding="utf-8")
    return spec / "roverlink.toml"


def _new_robot() -> str:
    """The TB6612 car as another reference robot: its own name, example and wheels."""
    text = REFERENCE.read_text(encoding="utf-8").replace('name = "diffdrive-tb6612"', 'name = "tiny"')
    text = text.replace('example = "DiffDriveTB6612"', 'example = "TinyCar"')
    return text.replace("wheel_diameter_m = 0.064", "wheel_diameter_m = 0.042")


def test_a_new_reference_robot_file_is_picked_up_by_the_generator(tmp_path: Path) -> None:
    """One file in protocol/robots/ is a new reference robot: its example's header, its profile
    and its docs column are generated with the others'."""
    spec = _tree(tmp_path, {"diffdrive-tb6612.toml": REFERENCE.read_text(), "tiny.toml": _new_robot()})
    out = generate.render(*generate.load(spec, tmp_path))
    header = out["arduino/RoverLink/examples/TinyCar/robot_profile.h"]
    assert header.startswith(
        "// DO NOT EDIT: generated from protocol/robots/tiny.toml by `python -m protocol generate`."
    )
    assert 'static const char NAME[] = "TinyCar";' in header
    assert "0x10, 0xA4, 0x00, 0x00,  // wheel_diameter_um = 42000" in header
    assert '"tiny": RobotProfile(' in out["protocol/generated/profiles.py"]
    assert "| `DiffDriveTB6612` | `TinyCar` |" in out["docs/robots.md"]
    # and the same reference header as the one file's own render (one writer)
    assert out["arduino/RoverLink/examples/DiffDriveTB6612/robot_profile.h"] == (
        ROOT / "arduino/RoverLink/examples/DiffDriveTB6612/robot_profile.h"
    ).read_text(encoding="utf-8")


@pytest.mark.parametrize(
    ("old", "new", "key", "problem"),
    [
        (
            "counts_per_rev = 1560",
            "counts_per_rev = 0",
            "encoders.counts_per_rev",
            "= 0: out of range (allowed: 1..65535",
        ),
        ('safe_state = "brake"', 'safe_state = "skid"', "limits.safe_state", "not one of coast, brake, ramp_down"),
        ('name = "diffdrive-tb6612"', 'name = "car"', "name", "a reference robot is named as its file"),
        ('example = "DiffDriveTB6612"', 'example = ""', "firmware.example", "names its firmware example"),
        ("{ a = 18, b = 19 }", "{ a = 40, b = 19 }", "encoders.pins[1].a", "pin 40 cannot interrupt on the MEGA2560"),
        ("[emulator.body]", "[emulator.bodyy]", "emulator.bodyy", "unknown part (did you mean 'body'?)"),
        ("mass_kg = 1.2", "mass_kg = -1.2", "emulator.body.mass_kg", "= -1.2: out of range (allowed: 0.01..1000 kg)"),
    ],
)
def test_a_bad_reference_robot_file_is_refused_naming_file_and_key(
    tmp_path: Path, old: str, new: str, key: str, problem: str
) -> None:
    text = REFERENCE.read_text(encoding="utf-8")
    assert old in text
    spec = _tree(tmp_path, {"diffdrive-tb6612.toml": text.replace(old, new, 1)})
    with pytest.raises(loader.SpecError) as info:
        generate.load(spec, tmp_path)
    message = str(info.value)
    assert message.startswith("protocol/robots/diffdrive-tb6612.toml"), message
    assert key in message and problem in message, message


def test_a_reference_robot_gives_the_emulator_its_motor(tmp_path: Path) -> None:
    text = REFERENCE.read_text(encoding="utf-8")
    start = text.index("[emulator.motor]")
    text = text[:start] + text[text.index("[emulator.body]") :]
    spec = _tree(tmp_path, {"diffdrive-tb6612.toml": text})
    with pytest.raises(loader.SpecError, match=r"emulator\.motor: missing: a reference robot gives its physics"):
        generate.load(spec, tmp_path)


def test_two_reference_robots_may_not_share_an_example(tmp_path: Path) -> None:
    twin = _new_robot().replace('example = "TinyCar"', 'example = "DiffDriveTB6612"')
    spec = _tree(tmp_path, {"diffdrive-tb6612.toml": REFERENCE.read_text(), "tiny.toml": twin})
    with pytest.raises(loader.SpecError, match="example: DiffDriveTB6612 is used by more than one reference robot"):
        generate.load(spec, tmp_path)


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
    text = (ROOT / "protocol" / "robots" / "diffdrive-bts7960.toml").read_text(encoding="utf-8")
    robot, problems = parse(text.replace("r_en = 22, l_en = 23", "r_en = 22, l_en = 22"), "bts.toml")
    assert robot is not None and not problems
    robot, problems = parse(text.replace("r_en = 24, l_en = 25", "r_en = 22, l_en = 25"), "bts.toml")
    assert robot is None
    assert any("drive.motors[1].r_en" in str(p) and "already serves drive.motors[0].r_en" in str(p) for p in problems)
    assert load(ROOT / "protocol" / "robots" / "diffdrive-tb6612.toml").wiring.motors[0].pin("standby") == 26


def test_the_examples_take_every_pin_from_the_generated_profile() -> None:
    """No sketch writes a pin number of its own: they all come from the robot files."""
    own_pin = re.compile(r"const\s+uint8_t\s+\w+\s*=\s*(?:\d+|A\d+)\s*;|PulseChannel::[ABC]\b")
    for profile in PROFILES.values():
        sketch = ROOT / "arduino/RoverLink/examples" / profile.example / f"{profile.example}.ino"
        text = sketch.read_text(encoding="utf-8")
        assert not own_pin.findall(text), sketch
        header = (sketch.parent / "robot_profile.h").read_text(encoding="utf-8")
        for part in profile.wiring.encoders:
            assert f"= {part.pin('a')};" in header and f"= {part.pin('b')};" in header


def test_every_key_comment_of_a_reference_file_says_what_the_schema_says() -> None:
    """The reference files are hand-written and are what `roverlink robot new --from` copies: each
    key's comment starts with the schema's unit and meaning (which docs/robot-file.md's tables
    show), and may go on to say why this robot has this value."""
    from protocol.robotfile.schema import SECTIONS

    wrong = []
    for path in sorted((ROOT / "protocol" / "robots").glob("*.toml")):
        section = ""
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            header = re.match(r"^\[\[?([\w.]+)\]\]?", line)
            if header:
                section = header.group(1)
                continue
            commented = re.match(r"^(\w+) = .*?  # (.*)$", line)
            if commented is None:
                continue
            key = {k.name: k for k in SECTIONS.get(section, ())}.get(commented.group(1))
            said = (f"[{key.unit}] " if key.unit else "") + key.doc if key is not None else "a key of the schema"
            if not commented.group(2).startswith(said):
                wrong.append(f"{path.name}:{number} [{section}] {commented.group(1)}: should say {said!r}")
    assert wrong == []
