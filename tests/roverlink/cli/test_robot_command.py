"""`roverlink robot new|check|show` over robot files (exit codes and output)."""

from __future__ import annotations

from pathlib import Path

import pytest

from protocol.robotfile import load
from roverlink.cli import main


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str]:
    code = main(["robot", *argv])
    out = capsys.readouterr()
    return code, out.out + out.err


def test_the_issue_scenario(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "my.toml"
    assert _run(capsys, "new", str(path), "--from", "picar")[0] == 0
    text = path.read_text(encoding="utf-8")
    assert "DO NOT EDIT" not in text and "# [m] Driven wheel diameter." in text
    path.write_text(text.replace("pin = 10 ", "pin = 6 "), encoding="utf-8")
    code, out = _run(capsys, "check", str(path))
    assert code == 2
    line = text.splitlines().index(next(x for x in text.splitlines() if x.startswith("pin = 10 "))) + 1
    expected = (
        "steering.pin: esc 9, servo 6: the ESC and servo pulses need the pins of one 16-bit timer (Timer1: pins 9, 10)"
    )
    assert out == f"{path}:{line}: {expected}\nroverlink robot check: {path}: 1 problem\n"
    edited = text.replace("track_m = 0.16", "track_m = 0.31").replace("wheelbase_m = 0.26", "wheelbase_m = 0.42")
    edited = edited.replace("wheel_diameter_m = 0.065", "wheel_diameter_m = 0.11")
    edited = edited.replace("x_m = 0.18  #", "x_m = 0.05  #").replace("z_m = 0.16  #", "z_m = 0.3  #")
    path.write_text(edited, encoding="utf-8")
    assert _run(capsys, "check", str(path)) == (0, f"{path}: ok\n")
    code, out = _run(capsys, "show", str(path))
    assert code == 0
    assert "metres per count      0.4800 mm (720 counts/rev)" in out
    assert (
        "flash (estimate)      about 15,296 B (47% of 32,256 B): the AckermannPiCar example's build, not this " in out
    )
    assert f"`roverlink firmware build --robot {path}` prints its own" in out


def test_new_refuses_to_overwrite_without_force(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "mine.toml"
    path.write_text("keep", encoding="utf-8")
    code, out = _run(capsys, "new", str(path), "--from", "diffdrive-tb6612")
    assert (code, path.read_text(encoding="utf-8")) == (1, "keep")
    assert "exists (--force to overwrite)" in out
    assert _run(capsys, "new", str(path), "--from", "diffdrive-tb6612", "--force")[0] == 0
    assert _run(capsys, "check", str(path)) == (0, f"{path}: ok\n")


def test_check_lists_every_problem_and_show_refuses_a_bad_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "bad.toml"
    assert _run(capsys, "new", str(path), "--from", "diffdrive-bts7960")[0] == 0
    text = (
        path.read_text(encoding="utf-8").replace("kp = 0.6", "kpp = 0.6").replace('board = "mega2560"', 'board = "due"')
    )
    path.write_text(text, encoding="utf-8")
    code, out = _run(capsys, "check", str(path))
    assert code == 2
    assert "pid.kpp: unknown key (did you mean 'kp'?)" in out
    assert "board: = 'due': not one of uno, mega2560, pico, native" in out
    assert _run(capsys, "show", str(path))[0] == 2
    none = tmp_path / "none.toml"
    assert _run(capsys, "check", str(none)) == (2, f"{none}: no such file\nroverlink robot check: {none}: 1 problem\n")


def test_new_on_a_pico_writes_the_robot_on_the_pico_pinout(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "pico_car.toml"
    code, out = _run(capsys, "new", str(path), "--from", "picar", "--board", "pico")
    assert code == 0 and "on the Pico pinout" in out
    text = path.read_text(encoding="utf-8")
    assert 'board = "pico"' in text and "# [m] Mount position" in text  # the comments kept
    assert _run(capsys, "check", str(path)) == (0, f"{path}: ok\n")
    robot = load(path)
    assert (robot.wiring.esc_pin, robot.wiring.servo_pin) == (2, 3)
    code, out = _run(capsys, "show", str(path))
    assert code == 0 and "on the pico" in out and "ring oscillator" in out
    assert "about 16,816 B (0.8% of 2,097,152 B): picar on the Pico's build" in out
