"""The examples run as documented, on every robot their docstring names, and the pytest plugin
works for a user's own test file."""

from __future__ import annotations

import re
import runpy
import subprocess
import sys
from pathlib import Path

import pytest

from host_sdk import PROFILES

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SCRIPTS = ["drive_square.py", "read_odometry.py", "tune_pid.py"]


def named_profiles(script: str) -> list[str]:
    """The emu:// profiles an example's docstring names (`python examples/x.py` alone: the default)."""
    doc = runpy.run_path(str(EXAMPLES / script))["__doc__"]
    return sorted(set(re.findall(r"emu://([a-z0-9-]+)", doc)) | {"diffdrive-tb6612"})


CASES = [(script, profile) for script in SCRIPTS for profile in named_profiles(script)]


def test_every_example_names_every_reference_robot() -> None:
    for script in SCRIPTS:
        assert set(named_profiles(script)) == set(PROFILES), script


@pytest.mark.parametrize(("script", "profile"), CASES, ids=[f"{s}-{p}" for s, p in CASES])
def test_example_runs_on_each_robot_it_names(script: str, profile: str, capsys: pytest.CaptureFixture[str]) -> None:
    module = runpy.run_path(str(EXAMPLES / script))
    module["main"](f"emu://{profile}?clock=virtual")
    out = capsys.readouterr().out
    assert out
    if script == "drive_square.py":
        assert "side 4:" in out
        last = re.findall(r"side 4: x=([-+.\d]+) m y=([-+.\d]+) m", out)[0]
        assert abs(float(last[0])) < 0.15 and abs(float(last[1])) < 0.15  # back near the start


def test_the_plugin_fixtures_work_in_a_users_test_run(tmp_path: Path) -> None:
    """`pytest examples/test_my_robot.py` in a fresh process: the plugin comes from the pytest11 entry point."""
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "--rootdir",
            str(tmp_path),
            str(EXAMPLES / "test_my_robot.py"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
        check=False,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "3 passed" in result.stdout


def test_demo_command_reports_odometry_against_truth(capsys: pytest.CaptureFixture[str]) -> None:
    from roverlink.cli import main

    assert main(["demo", "--fast", "--side", "0.5"]) == 0
    out = capsys.readouterr().out
    assert "position error" in out and "round trip (PING/PONG)" in out and "CRC / COBS / length errors" in out


def test_demo_plot_names_the_robot_and_the_course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from roverlink.cli import main
    from roverlink.commands import demo

    titles: list[str] = []
    real = demo.plot_module

    def spy() -> object:
        plt = real()
        original = plt.Axes.set_title

        def set_title(ax: object, title: str, *args: object, **kwargs: object) -> object:
            titles.append(title)
            return original(ax, title, *args, **kwargs)

        monkeypatch.setattr(plt.Axes, "set_title", set_title)
        return plt

    monkeypatch.setattr(demo, "plot_module", spy)
    target = tmp_path / "square.png"
    assert main(["demo", "--fast", "--profile", "picar", "--side", "0.8", "--plot", str(target)]) == 0
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert titles and "picar" in titles[-1] and "0.8 m square" in titles[-1] and "stream" in titles[-1]
