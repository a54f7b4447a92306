"""Every command says it failed the same way: `roverlink COMMAND: what went wrong` on stderr
(roverlink.say), never a bare `error:` line or a message without the command's name."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from roverlink.cli import main
from roverlink.commands import COMMANDS

ROOT = Path(__file__).resolve().parents[3]
NO_PORT = "/dev/roverlink-no-such-port"
MISSING = "/nonexistent/robot.toml"

FAILING = {
    "demo": ["demo", "--url", NO_PORT],
    "info": ["info", NO_PORT],
    "robot": ["robot", "show", MISSING],
    "emulate": ["emulate", "--robot", MISSING],
    "firmware": ["firmware", "build", "--robot", MISSING],
    "monitor": ["monitor", NO_PORT],
    "teleop": ["teleop", NO_PORT],
    "console": ["console", "--url", NO_PORT],
    "calibrate": ["calibrate", NO_PORT, "--no-imu"],
    "tune": ["tune", NO_PORT],
    "record": ["record", NO_PORT, "-o", "out.txt"],
    "ros2": ["ros2", "--url", NO_PORT],
    "follow": ["follow", "--url", NO_PORT],
    "decode": ["decode", "zz"],
}
"""One way each command fails (no board on the port, no such robot file, bad input)."""
CANNOT_FAIL = {"doctor", "ports", "cameras", "roundtrip", "spec"}
"""Commands that report what they find and have no failure of their own."""
PREFIXES = {"robot": "roverlink robot show: ", "firmware": "roverlink firmware build: "}


def test_every_command_is_listed_here() -> None:
    names = {module.__name__.rsplit(".", 1)[1] for module in COMMANDS}
    assert names == set(FAILING) | CANNOT_FAIL


@pytest.mark.parametrize("name", sorted(FAILING))
def test_a_failing_command_names_itself(
    name: str, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.chdir(tmp_path)
    if name == "ros2":  # fails the same way whether rclpy is installed or not: without it
        monkeypatch.setattr("roverlink.commands.ros2.missing_modules", lambda: ["rclpy"])
    assert main(FAILING[name]) != 0
    err = capsys.readouterr().err
    prefix = PREFIXES.get(name, f"roverlink {name}: ")
    assert err.startswith(prefix), err
    assert not re.search(r"^error:", err, re.MULTILINE), err


def test_no_command_prints_a_bare_error_line() -> None:
    """The rule has one place (roverlink/say.py): no command writes `error:` or its own name itself."""
    bad = []
    for path in sorted((ROOT / "roverlink").rglob("*.py")):
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if re.search(r"""print\(f?["'](error: |roverlink [a-z0-9 -]+: )""", line):
                bad.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}")
    assert bad == []


def test_robot_check_lists_the_problems_and_names_itself(capsys: pytest.CaptureFixture[str]) -> None:
    """Its findings are `FILE:LINE: ...` lines, as a linter writes them; the failure is said once more
    in the commands' form."""
    assert main(["robot", "check", MISSING]) == 2
    out, err = capsys.readouterr()
    assert out == f"{MISSING}: no such file\n"
    assert err == f"roverlink robot check: {MISSING}: 1 problem\n"


@pytest.mark.parametrize("command", [c.__name__.rsplit(".", 1)[-1] for c in COMMANDS])
def test_an_argument_a_command_does_not_take_is_reported_by_that_command(
    command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = [command, "--no-such-option"]
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    err = capsys.readouterr().err
    assert exit_.value.code == 2
    assert f"roverlink {command}: error: " in err and "roverlink: error:" not in err, err


def test_ros_parameters_before_ros_args_are_pointed_there(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["ros2", "--url", "emu://picar", "-p", "baud:=57600"])
    err = capsys.readouterr().err
    assert "unrecognized arguments: -p baud:=57600 (ROS arguments go after --ros-args" in err


def test_decode_names_the_word_that_is_not_hex(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["decode", "01", "zz"]) == 2
    err = capsys.readouterr().err
    assert "roverlink decode: not hex: 'zz' (give bytes as hex digit pairs" in err and "fromhex" not in err


def test_a_reader_that_goes_away_stops_a_command_quietly() -> None:
    """`roverlink info PTY | head -1`: the pipe closes under the command, which stops without a
    traceback (with 141, as a shell reports a command a pipe stopped)."""
    import os
    import subprocess
    import sys

    read_end, write_end = os.pipe()
    os.close(read_end)  # the reader is gone before the first line
    command = [sys.executable, "-m", "roverlink", "info", "emu://picar?clock=virtual"]
    try:
        result = subprocess.run(command, stdout=write_end, stderr=subprocess.PIPE, text=True, timeout=60, check=False)
    finally:
        os.close(write_end)
    assert "Traceback" not in result.stderr and "Exception ignored" not in result.stderr, result.stderr
    assert result.returncode == 141, result.stderr
