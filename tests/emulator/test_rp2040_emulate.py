"""`roverlink emulate --backend rp2040`: the Pico firmware in rp2040js served on a pty as real
hardware would be, for a reference robot moved to the Pico pinout (--profile) and for a user's
board = "pico" robot file (--robot), at 115200 and at 1 Mbaud; the SDK connects, arms and drives it.
A robot file for another board serves nothing (exit 2), nor a Pico's on simavr."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from host_sdk import Robot
from protocol.generated.enums import Board
from protocol.robotfile import reference_path
from protocol.robotfile.pico import on_pico
from tests.firmware.test_rp2040_harness import _require
from tests.support.emulate import emulate
from tests.support.wait import wait_until


def _drives(robot: Robot) -> None:
    robot.arm()

    def turning() -> bool:
        robot.drive(0.2, 0.0)
        sample = robot.wait_feedback()
        return min(sample.wheel_speeds_m_s) > 0.1

    wait_until(turning, 10.0, "both wheels turning at more than 0.1 m/s")


@pytest.mark.parametrize("baud", [115200, 1_000_000])
def test_a_reference_robot_on_a_pico_serves_and_drives(baud: int) -> None:
    _require()
    args = ("--backend", "rp2040", "--profile", "diffdrive-tb6612", "--baud", str(baud), "--quiet")
    with emulate(*args) as board, Robot.connect(board.url, baud=baud, profile="diffdrive-tb6612") as robot:
        assert robot.identity.board is Board.PICO and robot.identity.robot_name == "diffdrive-tb6612"
        _drives(robot)


def test_a_pico_robot_file_serves_its_name(tmp_path: Path) -> None:
    _require()
    path = tmp_path / "my_pico_car.toml"
    path.write_text(on_pico(reference_path("picar").read_text()).replace('name = "picar"', 'name = "my-pico-car"'))
    with emulate("--backend", "rp2040", "--robot", str(path), "--quiet") as board, Robot.connect(board.url) as robot:
        assert robot.identity.robot_name == "my-pico-car" and robot.identity.board is Board.PICO


def _emulate_exit(*args: str) -> subprocess.CompletedProcess[str]:
    command = [sys.executable, "-m", "roverlink", "emulate", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=120, check=False)


def test_a_file_for_another_board_serves_nothing(tmp_path: Path) -> None:
    result = _emulate_exit("--backend", "rp2040", "--robot", str(reference_path("picar")))
    assert result.returncode == 2 and result.stdout == ""
    assert 'board = "pico"' in result.stderr
    path = tmp_path / "pico.toml"  # and a Pico file on the AVR's backend is pointed to its own
    path.write_text(on_pico(reference_path("picar").read_text()))
    result = _emulate_exit("--backend", "simavr", "--robot", str(path))
    assert result.returncode == 2 and "its firmware runs with --backend rp2040" in result.stderr, result.stderr
