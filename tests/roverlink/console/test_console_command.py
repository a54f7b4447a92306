"""`roverlink console` as a user starts it, and the live-view address options of record, monitor and
follow: what they print, what they refuse."""

from __future__ import annotations

import re
import subprocess
import sys
import urllib.error
import urllib.request
from pathlib import Path

import pytest

from roverlink.cli import main
from tests.support.wait import Deadline

pytest.importorskip("aiohttp")
ROOT = Path(__file__).resolve().parents[3]


def status_of(url: str) -> int:
    try:
        with urllib.request.urlopen(url, timeout=5) as r:
            return int(r.status)
    except urllib.error.HTTPError as e:
        return e.code


def test_off_loopback_the_console_prints_a_url_with_its_token_and_wants_it() -> None:
    args = ["--world", "random:3", "--host", "0.0.0.0", "--port", "0", "--duration", "20", "--camera-fps", "5"]
    proc = subprocess.Popen(
        [sys.executable, "-m", "roverlink", "console", *args], cwd=ROOT, stderr=subprocess.PIPE, text=True
    )
    try:
        assert proc.stderr is not None
        deadline = Deadline(60)
        line = ""
        while "open " not in line:
            assert not deadline.expired() and proc.poll() is None, f"no URL printed: {line!r}"
            line = proc.stderr.readline()
        urls = re.findall(r"http://\S+", line)
        assert any(".local:" in u for u in urls), line  # the robot's name on the network too
        found = re.match(r"http://[^:/]+:(\d+)/\?token=([\w-]+)", urls[0])
        assert found, urls
        port, token = found.groups()
        assert len(token) >= 20
        base = f"http://127.0.0.1:{port}"
        assert status_of(base + "/") == 401  # loopback clients too, once it listens beyond loopback
        assert status_of(base + "/api/frame.jpg") == 401
        assert status_of(f"{base}/?token={token}") == 200
        wrong = token[:-1] + ("y" if token[-1] != "y" else "z")  # one character off (a token may end in x)
        assert status_of(f"{base}/?token={wrong}") == 401
    finally:
        proc.terminate()
        assert proc.wait(timeout=20) in (0, -15)


def test_on_a_robot_the_console_names_the_sensor_options_it_needs(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["console", "--url", "/dev/ttyACM0"]) == 2  # before it connects
    err = capsys.readouterr().err
    assert err.startswith("roverlink console: no lidar and no camera for this robot: give --lidar PORT, ")
    assert "[sensors.camera] source in the --robot FILE" in err


def test_a_port_out_of_range_is_refused_naming_the_range(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["console", "--port", "70000"])
    assert "0 to 65535" in capsys.readouterr().err


def test_record_serves_its_live_view_on_the_address_asked_and_says_it_is_open(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "r.mcap"
    code = main(
        [
            "record",
            "emu://picar?clock=virtual",
            "-o",
            str(out),
            "--duration",
            "0.5",
            "--foxglove",
            "--foxglove-host",
            "0.0.0.0",
            "--foxglove-port",
            "0",
        ]
    )
    assert code == 0
    err = capsys.readouterr().err
    assert re.search(r"live view: ws://127\.0\.0\.1:\d+", err), err  # from this machine
    assert re.search(r"from another machine: ws://\S+\.local:\d+", err) and "no access control" in err
    code = main(
        [
            "record",
            "emu://picar?clock=virtual",
            "-o",
            str(out),
            "--force",
            "--duration",
            "0.5",
            "--foxglove",
            "--foxglove-port",
            "0",
        ]
    )
    assert code == 0
    err = capsys.readouterr().err
    assert re.search(r"live view: ws://127\.0\.0\.1:\d+", err) and "no access control" not in err


def test_bad_tokens_and_addresses_are_named_before_anything_starts(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["console", "--token", "abc"]) == 2
    err = capsys.readouterr().err
    assert "--token" in err and "at least 8" in err and "'abc'" not in err  # a secret is not echoed
    assert main(["console", "--host", "nosuch.invalid", "--duration", "1"]) == 1
    err = capsys.readouterr().err
    assert "cannot listen on nosuch.invalid:8080" in err and "(--host, --port)" in err


def test_the_console_runs_a_robot_file_on_the_emulator(capsys: pytest.CaptureFixture[str]) -> None:
    robot_file = ROOT / "protocol" / "robots" / "picar.toml"
    assert main(["console", "--robot", str(robot_file), "--port", "0", "--duration", "2", "--camera-fps", "5"]) == 0
    assert re.search(r"open http://127\.0\.0\.1:\d+/$", capsys.readouterr().err.strip())


def test_autonomous_following_is_said_at_the_start(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["console", "--port", "0", "--duration", "2", "--camera-fps", "5", "--autonomous"]) == 0
    assert "--autonomous: following goes on with no browser open" in capsys.readouterr().err
