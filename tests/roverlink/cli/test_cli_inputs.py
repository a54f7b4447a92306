"""The `roverlink` command with bad input: argparse-style errors and exit 2 before any work, exit
statuses that mean something, help that reads like a finished tool, and no value that runs forever."""

from __future__ import annotations

import argparse
import importlib
from collections.abc import Iterator
from typing import Any

import pytest

from host_sdk import messages
from host_sdk.framing import encode_frame
from roverlink.cli import build_parser, main

BAD_OPTIONS = [
    ("demo", "--fast", "--side", "nan"),
    ("demo", "--fast", "--side", "inf"),
    ("demo", "--fast", "--side", "0"),
    ("demo", "--fast", "--speed", "0"),
    ("demo", "--fast", "--speed", "1e-9"),
    ("demo", "--fast", "--speed", "-0.3"),
    ("demo", "--seed", "-1"),
    ("demo", "--baud", "0"),
    ("emulate", "--speed", "inf"),
    ("emulate", "--speed", "0"),
    ("emulate", "--latency-ms", "nan"),
    ("emulate", "--latency-ms", "inf"),
    ("emulate", "--socket", "99999"),
    ("emulate", "--socket", "-1"),
    ("emulate", "--drift-ppm", "nan"),
    ("emulate", "--bootloader-ms", "-5"),
    ("emulate", "--seed", str(2**64)),
    ("emulate", "--baud", "fast"),
    ("info", "emu://", "--timeout", "nan"),
    ("info", "emu://", "--timeout", "0"),
    ("info", "emu://", "--baud", "-9600"),
]


@pytest.mark.parametrize("argv", BAD_OPTIONS, ids=" ".join)
def test_bad_numeric_options_stop_before_any_work_with_exit_2(
    argv: tuple[str, ...], capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(list(argv))
    assert exit_.value.code == 2
    out, err = capsys.readouterr()
    option = next(a for a in argv if a.startswith("--") and a != "--fast")
    assert f"error: argument {option}:" in err and "is not" in err
    assert out == ""  # nothing started: no pty path, no connection


def test_lockstep_demo_on_a_robot_without_it_says_which_option_to_use(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--profile", "picar", "--mode", "lockstep", "--fast"]) == 2
    err = capsys.readouterr().err
    assert "--mode stream" in err and "mode='stream'" not in err


def test_demo_on_a_url_drives_the_boards_own_robot_and_names_no_other(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--url", "emu://picar?clock=virtual", "--side", "0.3"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("RoverLink demo: emu://picar?clock=virtual (stream feedback)\n"), out[:200]
    assert "connected to AckermannPiCar" in out and "diffdrive" not in out


def test_demo_plot_without_matplotlib_fails_before_driving(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    real = importlib.import_module

    def no_matplotlib(name: str, *args: Any) -> Any:
        if name.startswith("matplotlib"):
            raise ImportError(f"No module named {name!r}")
        return real(name, *args)

    monkeypatch.setattr(importlib, "import_module", no_matplotlib)
    assert main(["demo", "--fast", "--plot", "never.png"]) == 1
    out, err = capsys.readouterr()
    assert "connected" not in out and "leg 1/4" not in out
    assert "--plot needs matplotlib" in err and "pip install" in err and "[plot]" in err


def test_the_slowest_allowed_demo_still_finishes(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["demo", "--fast", "--side", "0.1", "--speed", "0.05"]) == 0
    assert "position error" in capsys.readouterr().out


def test_decode_shows_fields_and_exits_1_on_a_bad_crc(capsys: pytest.CaptureFixture[str]) -> None:
    good = encode_frame(messages.SetWheelSpeeds(left_mm_s=300, right_mm_s=-200), seq=5)
    assert main(["decode", good.hex()]) == 0
    out = capsys.readouterr().out
    assert "SET_WHEEL_SPEEDS (0x20) seq 5" in out and "left_mm_s   300 mm/s" in out and "Container" not in out
    bad = bytearray(good)
    bad[-2] ^= 0x01
    assert main(["decode", bytes(bad).hex()]) == 1
    out = capsys.readouterr().out
    assert "BAD crc" in out and "computed" in out
    assert main(["decode", "zz"]) == 2


def _parsers(parser: argparse.ArgumentParser) -> Iterator[tuple[str, argparse.ArgumentParser]]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield name, sub
                yield from ((f"{name} {n}", p) for n, p in _parsers(sub))


def test_help_reads_like_a_finished_tool(capsys: pytest.CaptureFixture[str]) -> None:
    """Every command has a description and every option says what it is."""
    for name, parser in _parsers(build_parser()):
        assert parser.description, f"roverlink {name} has no description"
        for action in parser._actions:
            if not isinstance(action, (argparse._HelpAction, argparse._SubParsersAction)):
                assert action.help, f"roverlink {name} {'/'.join(action.option_strings) or action.dest} has no help"
    with pytest.raises(SystemExit) as exit_:
        main(["firmware", "flash", "--help"])
    assert exit_.value.code == 0
    text = capsys.readouterr().out
    assert "default: all" not in text and "example sketch of the library to flash" in text
