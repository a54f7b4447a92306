"""`roverlink firmware build | sketch | flash --robot FILE`: the firmware of a user's robot file, built
with avr-gcc from the example that fits it and the robot_profile.h generated from the file, in a
build folder of its own (never the library's). A file with any problem builds nothing (exit 2)."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from protocol.robotfile import load, reference_path
from roverlink.cli import main as cli_main
from roverlink.firmware.robot import build_folder, firmware_problems
from tests.support.avr_build import LIBRARY, ROOT, firmware_cli, require_toolchain

UNO_FREE_FRACTION = 0.50  # the reference firmware's budget (test_avr_build.py), met by a file's too


def _my_car(tmp_path: Path, *changes: tuple[str, str]) -> Path:
    """`roverlink robot new --from picar`, with another wheel and wheelbase (pins unchanged)."""
    path = tmp_path / "my_car.toml"
    assert cli_main(["robot", "new", str(path), "--from", "picar"]) == 0
    text = path.read_text()
    for old, new in (
        ('name = "picar"', 'name = "my-car"'),
        ("wheel_diameter_m = 0.065", "wheel_diameter_m = 0.0712"),
        ("wheelbase_m = 0.26", "wheelbase_m = 0.235"),
        *changes,
    ):
        assert old in text
        text = text.replace(old, new)
    path.write_text(text)
    return path


def _library_status() -> str:
    return subprocess.run(
        ["git", "status", "--porcelain", "--", str(LIBRARY)], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout


def test_build_from_a_robot_file(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    record_property: pytest.RecordProperty,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    require_toolchain()
    before = _library_status()
    path = _my_car(tmp_path, ("min_deg = 65.0", "min_deg = 70.0"), ("step_deg = 15.0", "step_deg = 10.0"))
    here = tmp_path / "here"
    here.mkdir()
    monkeypatch.chdir(here)  # the firmware goes where the user is, not into the checkout's build/
    code, out, err = firmware_cli(capsys, "firmware", "build", "--robot", str(path))
    assert code == 0, err
    folder = build_folder(path)
    hex_file = here / "firmware" / "my_car" / "uno" / "AckermannPiCar.hex"
    assert str(hex_file) in out and hex_file.is_file()
    # The sketch's first comment is the file's robot, not the reference PiCar's.
    ino = (folder / "AckermannPiCar" / "AckermannPiCar.ino").read_text()
    words = " ".join(line.removeprefix("//").strip() for line in ino.splitlines())
    assert "steering servo 70..125 degrees, centre 90, 10 degree steps" in words
    assert "A brushless motor behind an RC ESC" not in words  # the example's account of the reference PiCar
    assert ino.startswith("// my-car: ackermann drive (ESC+servo) on the uno")
    header = (folder / "AckermannPiCar" / "robot_profile.h").read_text()
    assert header.startswith(f"// DO NOT EDIT: generated from {path}")
    assert 'static const char NAME[] = "my-car";' in header
    assert "// wheel_diameter_um = 71200" in header
    assert "static const uint8_t ESC_PIN = 9;" in header
    # The budgets of the reference firmware hold for the file's.
    flash, flash_max, sram, sram_max = (int(x.replace(",", "")) for x in _figures(out))
    record_property("robot_file.AckermannPiCar.uno.flash_bytes", flash)
    record_property("robot_file.AckermannPiCar.uno.sram_bytes", sram)
    assert flash <= (1 - UNO_FREE_FRACTION) * flash_max and sram <= (1 - UNO_FREE_FRACTION) * sram_max
    assert _library_status() == before  # the library and its examples are not written


def _figures(out: str) -> tuple[str, str, str, str]:
    m = re.search(r"flash ([\d,]+) / ([\d,]+) B .*SRAM ([\d,]+) / ([\d,]+) B", out)
    assert m, out
    return m.group(1), m.group(2), m.group(3), m.group(4)


@pytest.mark.parametrize("command", [("build",), ("flash", "--port", "/dev/null", "--dry-run")])
def test_a_file_with_a_pin_error_builds_and_flashes_nothing(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, command: tuple[str, ...]
) -> None:
    path = _my_car(tmp_path, ("[esc]\npin = 9", "[esc]\npin = 8"), ("max_deg = 125.0", "max_deg = 190.0"))
    code, out, err = firmware_cli(capsys, "firmware", command[0], "--robot", str(path), *command[1:])
    assert code == 2
    assert "esc.pin" in err and "8" in err and "Timer1" in err  # every problem, each with its key
    assert "steering.max_deg" in err and "190" in err
    assert "avrdude" not in out
    assert not build_folder(path).exists()


def test_a_file_the_example_cannot_drive_is_refused(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """Problems beyond the file's own checks: what the chosen example relies on, and the name."""
    lights = "\n[lights]\nfront_left = 4\nfront_right = 5\nrear_left = 6\nrear_right = 7\n\n[sensors.lidar]"
    path = _my_car(tmp_path, ("\n[sensors.lidar]", lights), ('name = "my-car"', 'name = "' + "x" * 30 + '"'))
    code, _, err = firmware_cli(capsys, "firmware", "build", "--robot", str(path))
    assert code == 2
    assert "lights" in err and "AckermannPiCar example drives no lights" in err
    assert "name" in err and "at most 24 characters" in err
    assert not build_folder(path).exists()


def test_sketch_folder_builds_as_a_sketch(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    require_toolchain()
    path = _my_car(tmp_path)
    sketch = tmp_path / "MyCar"
    code, _, err = firmware_cli(capsys, "firmware", "sketch", "--robot", str(path), str(sketch))
    assert code == 0, err
    assert sorted(p.name for p in sketch.iterdir()) == ["MyCar.ino", "robot_profile.h"]
    assert "// wheel_diameter_um = 71200" in (sketch / "robot_profile.h").read_text()
    assert firmware_cli(capsys, "firmware", "sketch", "--robot", str(path), str(sketch))[0] == 2  # not overwritten
    code, _, err = firmware_cli(
        capsys, "firmware", "build", "--sketch", str(sketch), "--board", "uno", "--out", str(tmp_path)
    )
    assert code == 0, err
    assert (tmp_path / "MyCar.hex").is_file()


def test_flash_dry_run_names_the_files_firmware(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _my_car(tmp_path)
    monkeypatch.chdir(tmp_path)
    code, out, _ = firmware_cli(
        capsys, "firmware", "flash", "--robot", str(path), "--port", "/dev/ttyACM0", "--dry-run"
    )
    assert code == 0
    hex_file = tmp_path.resolve() / "firmware" / "my_car" / "uno" / "AckermannPiCar.hex"
    assert f"# build first: roverlink firmware build --robot {path}" in out
    assert f"avrdude -p atmega328p -c arduino -P /dev/ttyACM0 -b 115200 -U flash:w:{hex_file}:i" in out


def test_board_must_agree_with_the_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, _, err = firmware_cli(
        capsys, "firmware", "build", "--robot", str(reference_path("picar")), "--board", "mega2560"
    )
    assert code == 2 and "is for the uno, not the mega2560" in err


def test_a_firmware_build_refuses_an_example_the_library_lacks(tmp_path: Path) -> None:
    path = tmp_path / "mine.toml"
    path.write_text(reference_path("picar").read_text().replace('example = "AckermannPiCar"', 'example = "NoSuch"'))
    problems = [str(p) for p in firmware_problems(load(path))]
    assert any("firmware.example: = 'NoSuch': not an example sketch of the library (one of" in p for p in problems)
