"""The examples run as documented, on every robot their docstring names, and the pytest plugin
works for a user's own test file."""

from __future__ import annotations

import ast
import json
import re
import runpy
import shlex
import subprocess
import sys
import urllib.request
from pathlib import Path

import pytest

from host_sdk import PROFILES

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
SCRIPTS = ["drive_square.py", "read_odometry.py", "tune_pid.py"]


def named_profiles(script: str) -> list[str]:
    """The emu:// profiles an example's docstring names (`.venv/bin/python examples/x.py` alone: the default)."""
    doc = runpy.run_path(str(EXAMPLES / script))["__doc__"]
    return sorted(set(re.findall(r"emu://([a-z0-9-]+)", doc)) | {"diffdrive-tb6612"})


CASES = [(script, profile) for script in SCRIPTS for profile in named_profiles(script)]


def test_example_headers_run_as_a_newcomer_types_them() -> None:
    """Debian has no `python` outside a venv and refuses an unquoted `pip install roverlink[dev]`
    in zsh (a glob): the headers say the checkout's `.venv/bin/python` and quote the extras."""
    for path in sorted(EXAMPLES.glob("*.py")):
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
        assert not re.search(r"^\s*python3? examples/", doc, re.M), path.name
        assert not re.search(r"pip install roverlink\[", doc), path.name
        for line in re.findall(r"^\s*(\S*python \S*examples/\S+)", doc, re.M):
            assert line.startswith(".venv/bin/python "), (path.name, line)


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
    # The clocks' offset (the board counts from its boot) means nothing to a reader: its drift is shown.
    assert "clock offset" not in out
    assert re.search(r"board clock drift +[+-]\d+\.\d ppm against the host's \(time sync corrects it\)", out), out


def test_demo_plot_names_the_robot_and_the_course(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("matplotlib", reason="the plot extra (the full suite has it)")
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
    # The PiCar cannot turn in place: the title says its corners and the path's real size.
    corners = re.search(r"0\.8 m square, (\d\.\d\d) m radius corners: a (\d\.\d\d) x (\d\.\d\d) m path", titles[-1])
    assert corners, titles[-1]
    assert float(corners[1]) > 0.3 and float(corners[2]) > 0.8 and float(corners[3]) > 0.8


def test_demo_plot_shows_both_lines_where_they_coincide() -> None:
    pytest.importorskip("matplotlib", reason="the plot extra (the full suite has it)")
    from host_sdk import LinkStatistics, Pose
    from roverlink.commands import demo

    square = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0)]
    track = demo.Track(odometry=list(square), truth=list(square))
    result = demo.DemoResult(Pose(0.0, 0.0, 0.0, 0.0, 0.0, 0), (0.0, 0.0, 0.0), LinkStatistics(), track, 10.0)
    fig = demo.figure(result)
    truth, odometry = fig.axes[0].get_lines()
    assert truth.get_color() != odometry.get_color()
    # the odometry drawn on top and narrower, so the truth shows on both sides of it
    assert odometry.get_zorder() > truth.get_zorder() and odometry.get_linewidth() < truth.get_linewidth() / 2
    assert odometry.get_linestyle() == "-"  # a dashed line over a band hides its gaps in the band
    assert fig.axes[0].get_title().startswith("RoverLink demo: 1 m square, turns in place: a 1.00 x 1.00 m path")
    demo.plot_module().close(fig)


ASYNC_SERVER = EXAMPLES / "async_server.py"


def async_server_commands() -> list[list[str]]:
    """The arguments of the emulator command lines in examples/async_server.py's docstring."""
    doc = runpy.run_path(str(ASYNC_SERVER))["__doc__"]
    lines = re.findall(r"^\.venv/bin/python examples/async_server\.py([^#\n]*)", doc, re.M)
    return [args for args in map(shlex.split, lines) if not args or args[0].startswith("emu://")]


def test_the_async_server_example_documents_both_clocks() -> None:
    urls = [args[0] if args else "emu://" for args in async_server_commands()]
    assert urls == ["emu://", "emu://diffdrive-tb6612?clock=virtual"]


@pytest.mark.parametrize("args", async_server_commands(), ids=["real-clock", "virtual-clock"])
def test_the_async_server_example_serves_odometry_while_it_drives(args: list[str]) -> None:
    """Run as documented, with a short --seconds (robot clock) and any free port; fetch the JSON once."""
    seconds = "20" if "clock=virtual" in " ".join(args) else "2"
    command = [sys.executable, str(ASYNC_SERVER), *args, "--port", "0", "--seconds", seconds]
    with subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as proc:
        try:
            assert proc.stdout is not None
            first = proc.stdout.readline()  # printed once the server listens, before driving
            port = re.fullmatch(r"serving http://127\.0\.0\.1:(\d+)/odometry\n", first)
            assert port, first
            with urllib.request.urlopen(f"http://127.0.0.1:{port.group(1)}/odometry", timeout=30) as response:
                odometry = json.load(response)
            out, err = proc.communicate(timeout=120)
        finally:
            proc.kill()
    assert {"x_m", "y_m", "theta_rad", "linear_m_s", "angular_rad_s", "time_s", "state"} <= odometry.keys()
    assert proc.returncode == 0, err
    done = re.search(r"^done: x=([-+.\d]+) m y=([-+.\d]+) m", out, re.M)
    assert done and abs(float(done.group(1))) + abs(float(done.group(2))) > 0.1  # it drove


def test_the_asyncio_section_of_the_sdk_doc_runs_as_documented(capsys: pytest.CaptureFixture[str]) -> None:
    doc = (EXAMPLES.parent / "docs" / "sdk.md").read_text(encoding="utf-8")
    section = doc[doc.index("## asyncio") : doc.index("## Layering")]
    code = re.findall(r"```python\n(.*?)```", section, re.S)[0]
    exec(compile(code, "docs/sdk.md", "exec"), {})
    claimed = re.search(r"print\(.*\)\s+# (.*)", code)
    assert claimed and capsys.readouterr().out.strip() == claimed.group(1)
