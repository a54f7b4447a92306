"""`roverlink tune --robot FILE`: the gains found go into the file's [pid] (per wheel where they
differ), shown and asked first, so the next connect with the file keeps them; a connect whose file
changes the board's gains says so in one line."""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import pytest

from emulator.firmware.config import IMAGE_ADDR, IMAGE_SIZE, decode_image
from host_sdk import PidGains, Robot, RobotDescription
from protocol.robotfile import load, parse
from roverlink.cli import main
from roverlink.commands import tune
from roverlink.commands.tune import write_gains
from roverlink.interactive import ConsolePrompter

URL = "emu://diffdrive-tb6612?clock=virtual&stand=1&seed=5"
USER_NOTE = "# gains: my notes\n"


def _my_file(tmp_path: Path) -> Path:
    path = tmp_path / "my.toml"
    assert main(["robot", "new", str(path), "--from", "diffdrive-tb6612"]) == 0
    text = path.read_text(encoding="utf-8")
    path.write_text(text.replace("[pid]\n", f"{USER_NOTE}[pid]\n"), encoding="utf-8")
    return path


def _answers(*lines: str) -> tuple[ConsolePrompter, io.StringIO]:
    out = io.StringIO()
    return ConsolePrompter(out=out, inp=io.StringIO("".join(f"{a}\n" for a in lines))), out


def test_per_wheel_gains_are_written_after_the_change_is_shown(tmp_path: Path) -> None:
    path = _my_file(tmp_path)
    before = path.read_text(encoding="utf-8")
    with Robot.connect(URL, robot=path) as robot:
        robot.set_pid(kp=5.321, ki=47.52, kd=0.0, kf=1.25, ks=70.0, wheel=0)
        robot.set_pid(kp=4.75, ki=47.52, kd=0.0, kf=1.5, ks=70.0, wheel=1)
        # Asked and refused: the file stays as it was, and the lines to set are named.
        prompter, out = _answers("n")
        lines = write_gains(robot, RobotDescription.load(path), prompter)
        assert path.read_text(encoding="utf-8") == before
        assert "-kp = 1.0" in out.getvalue() and "+kp = [5.321, 4.75]" in out.getvalue()
        assert lines[-1] == "to keep them, set in [pid]: kp = [5.321, 4.75], ki = 47.52, kf = [1.25, 1.5]"
        prompter, _ = _answers("y")
        assert write_gains(robot, RobotDescription.load(path), prompter)[0].startswith(f"written to {path} [pid]")
    after = path.read_text(encoding="utf-8")
    assert USER_NOTE in after  # the user's lines kept, only the gains' lines changed
    changed = [(a, b) for a, b in zip(before.splitlines(), after.splitlines(), strict=True) if a != b]
    assert [b.split("  #")[0] for _, b in changed] == ["kp = [5.321, 4.75]", "ki = 47.52", "kf = [1.25, 1.5]"]
    pid = load(path).pid
    assert pid.per_wheel == ((5.321, 47.52, 0.0, 1.25, 70.0), (4.75, 47.52, 0.0, 1.5, 70.0)) and pid.differ
    # The next connect with the file (a new emulated board, at its compiled defaults) gets each wheel's.
    with Robot.connect(URL, robot=path) as robot:
        assert robot.pid(0) == PidGains(5.321, 47.52, 0.0, 1.25, 70.0)
        assert robot.pid(1) == PidGains(4.75, 47.52, 0.0, 1.5, 70.0)


def test_a_connect_that_changes_the_boards_gains_says_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _my_file(tmp_path)
    with Robot.connect(URL, robot=path) as robot:
        assert robot.gains_notice is None  # the board already runs the file's gains
    text = path.read_text(encoding="utf-8")
    path.write_text(text.replace("kp = 1.0", "kp = [1.0, 5.321]").replace("ki = 6.0", "ki = [6.0, 47.52]"))
    with Robot.connect(URL, robot=path) as robot:
        assert robot.pid(0) == PidGains(1.0, 6.0, 0.0, 1.25, 70.0)
        assert robot.pid(1) == PidGains(5.321, 47.52, 0.0, 1.25, 70.0)
        notice = robot.gains_notice
    assert notice == f"{path} [pid] set on the board (its stored gains differ): wheel 1 kp 1 -> 5.321, ki 6 -> 47.52"
    assert main(["info", URL, "--robot", str(path)]) == 0
    assert capsys.readouterr().err.count(f"note: {notice}") == 1


def test_tune_auto_save_writes_the_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _my_file(tmp_path)
    boards = []
    connect = tune.connect

    def kept(*args: Any, **kwargs: Any) -> Robot:
        robot = connect(*args, **kwargs)
        boards.append(robot.emulator)
        return robot

    monkeypatch.setattr(tune, "connect", kept)
    code = main(["tune", URL, "--robot", str(path), "--auto", "--save", "--yes", "--plot", "", "--speed", "0.24"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "saved to EEPROM" in out and f"written to {path} [pid]" in out and "+kp = " in out
    pid = load(path).pid
    [board] = boards
    _status, _config, stored = decode_image(bytes(board.eeprom[IMAGE_ADDR : IMAGE_ADDR + IMAGE_SIZE]))
    assert stored is not None
    for wheel in (0, 1):  # the file holds what tune saved, wheel by wheel
        assert pid.of_wheel(wheel) == pytest.approx(
            (stored[wheel].kp, stored[wheel].ki, stored[wheel].kd, stored[wheel].kf, stored[wheel].ks), rel=1e-6
        )


def test_a_gain_list_needs_one_gain_per_wheel(tmp_path: Path) -> None:
    text = _my_file(tmp_path).read_text(encoding="utf-8")
    robot, problems = parse(text.replace("kp = 1.0", "kp = [1.0, 2.0, 3.0]"), "my.toml")
    assert robot is None and [p.key for p in problems] == ["pid.kp"]
    assert "one gain per wheel channel (2)" in str(problems[0])
    robot, problems = parse(text.replace("ki = 6.0", "ki = [6.0, -1.0]"), "my.toml")
    assert robot is None and "out of range" in str(problems[0])
