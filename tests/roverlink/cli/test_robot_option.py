"""`--robot FILE` on the commands that connect: a bad file ends the command with exit 2 and every
problem before anything connects; a good one is used; a board unlike the file is an error
naming both sides, or with --allow-mismatch a warning."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from protocol.robotfile import reference_path
from roverlink.cli import main

URL = "emu://diffdrive-tb6612?clock=virtual"
BAD = 'name = "x"\nboard = "uno"\n[drive]\nkind = "differentail"\ndriver = "TB6612"\n[geometry]\nwheel_diameter_m = 5\n'
COMMANDS = [
    ["info", URL],
    ["teleop", URL],
    ["monitor", URL],
    ["tune", URL],
    ["calibrate", URL],
    ["record", URL],
    ["demo"],
    ["ros2"],
]


@pytest.mark.parametrize("argv", COMMANDS, ids=lambda a: a[0])
def test_a_bad_robot_file_ends_the_command_with_exit_2_and_every_problem(
    argv: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(BAD, encoding="utf-8")
    with pytest.raises(SystemExit) as exit_:
        main([*argv, "--robot", str(bad)])
    assert exit_.value.code == 2
    out, err = capsys.readouterr()
    assert out == ""  # nothing connected
    assert f"argument --robot: {bad}:" in err
    assert f"{bad}:4: drive.kind: = 'differentail'" in err
    assert f"{bad}:7: geometry.wheel_diameter_m: = 5: out of range" in err
    assert "missing section [limits]" in err


def test_a_missing_robot_file_is_named(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["info", URL, "--robot", str(tmp_path / "none.toml")])
    assert exit_.value.code == 2
    assert "none.toml: no such file" in capsys.readouterr().err


def test_info_with_the_boards_own_file(capsys: pytest.CaptureFixture[str]) -> None:
    path = reference_path("diffdrive-tb6612")
    assert main(["info", URL, "--robot", str(path)]) == 0
    out = capsys.readouterr().out
    assert "DiffDriveTB6612" in out
    assert f"kinematics DiffDrive (from {path}):" in out  # the file's, not the profile's


def test_a_board_unlike_the_file_fails_or_warns_with_allow_mismatch(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = reference_path("diffdrive-tb6612").read_text(encoding="utf-8")
    mine = tmp_path / "my.toml"
    mine.write_text(text.replace("wheel_diameter_m = 0.064", "wheel_diameter_m = 0.065"), encoding="utf-8")
    assert main(["info", URL, "--robot", str(mine)]) == 1
    err = capsys.readouterr().err
    assert "geometry.wheel_diameter_m = 0.065 m but the board" in err and "wheel_diameter_um = 64000 (0.064 m)" in err
    assert main(["info", URL, "--robot", str(mine), "--allow-mismatch"]) == 0
    out, err = capsys.readouterr()
    assert "warning:" in err and "wheel_diameter_um = 64000" in err and "DiffDriveTB6612" in out


def test_each_allowed_difference_is_one_line_on_a_terminal(tmp_path: Path) -> None:
    """As a user runs it (no logging set up, unlike under pytest): the command's `warning:` line,
    not the SDK's log line for the same difference as well."""
    text = reference_path("diffdrive-tb6612").read_text(encoding="utf-8")
    mine = tmp_path / "my.toml"
    mine.write_text(text.replace("wheel_diameter_m = 0.064", "wheel_diameter_m = 0.065"), encoding="utf-8")
    argv = ["info", URL, "--robot", str(mine), "--allow-mismatch"]
    done = subprocess.run(
        [sys.executable, "-m", "roverlink.cli", *argv], check=False, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert done.stderr.count("wheel_diameter_m = 0.065") == 1, done.stderr


def test_robot_and_profile_exclude_each_other(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["teleop", URL, "--profile", "picar", "--robot", str(reference_path("picar"))])
    assert exit_.value.code == 2
    assert "not allowed with argument" in capsys.readouterr().err
