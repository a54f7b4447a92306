"""`roverlink cameras`: what this machine can open, on this machine (no camera), a fake /sys and
/dev tree, and a fake picamera2; --json and --probe."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from roverlink.cli import main
from tests.support import fake_picamera2
from tests.support.fake_picamera2 import IMX219


def fake_tree(root: Path, nodes: dict[str, tuple[str, str]]) -> Path:
    """/sys/class/video4linux/videoN/{name,index} and /dev/videoN under `root`."""
    for node, (name, index) in nodes.items():
        sysfs = root / "sys" / "class" / "video4linux" / node
        sysfs.mkdir(parents=True)
        (sysfs / "name").write_text(name + "\n")
        (sysfs / "index").write_text(index + "\n")
        (root / "dev").mkdir(exist_ok=True)
        (root / "dev" / node).write_bytes(b"")
    return root


def test_no_camera_says_so_and_how_cameras_show_up(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    fake_picamera2.hide(monkeypatch)
    assert main(["cameras", "--root", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "no cameras found on this machine" in out and "--camera /dev/video0" in out and "--camera picamera2" in out
    assert "picamera2: not available: the Python module 'picamera2' is not importable" in out
    assert "sudo apt install python3-picamera2" in out
    assert "OpenCV " in out and "GStreamer no" in out  # the PyPI wheel this venv has


def test_this_machine_exits_0(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["cameras"]) == 0
    assert "picamera2:" in capsys.readouterr().out


def test_v4l2_nodes_from_sysfs_with_names_and_what_cannot_be_opened(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    fake_picamera2.hide(monkeypatch)
    root = fake_tree(
        tmp_path,
        {
            "video0": ("HD Pro Webcam C920", "0"),
            "video1": ("HD Pro Webcam C920", "1"),
            "video10": ("bcm2835-codec-decode", "0"),
            "video2": ("USB2.0 Camera", "0"),
        },
    )
    locked = root / "dev" / "video2"
    real_access = os.access
    monkeypatch.setattr(os, "access", lambda p, mode: False if str(p) == str(locked) else real_access(p, mode))
    assert main(["cameras", "--root", str(root), "--json"]) == 0
    listing = json.loads(capsys.readouterr().out)
    cams = {c["value"]: c for c in listing["cameras"]}
    assert list(cams) == ["/dev/video0", "/dev/video1", "/dev/video2", "/dev/video10"]  # numeric order
    assert cams["/dev/video0"] == {
        "value": "/dev/video0",
        "route": "v4l2",
        "name": "HD Pro Webcam C920",
        "usable": True,
        "note": "",
    }
    assert not cams["/dev/video1"]["usable"] and "metadata node" in cams["/dev/video1"]["note"]
    assert not cams["/dev/video10"]["usable"] and "not a camera" in cams["/dev/video10"]["note"]
    assert "add yourself to the video group" in cams["/dev/video2"]["note"]
    assert listing["opencv"]["gstreamer"] is False and listing["opencv"]["ffmpeg"] is True
    assert main(["cameras", "--root", str(root)]) == 0
    text = capsys.readouterr().out
    assert "--camera /dev/video0" in text and "HD Pro Webcam C920" in text and "(/dev/video1)" in text


def test_picamera2_cameras_are_listed_and_probed(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    fake = fake_picamera2.install(monkeypatch, [IMX219])
    assert main(["cameras", "--root", str(tmp_path), "--probe", "--seconds", "0.2", "--json"]) == 0
    listing = json.loads(capsys.readouterr().out)
    assert listing["picamera2"] is None
    (cam,) = listing["cameras"]
    assert (cam["value"], cam["route"], cam["name"], cam["usable"]) == ("picamera2:0", "picamera2", "imx219", True)
    assert cam["probe"]["size"] == [640, 480] and cam["probe"]["error"] is None and cam["probe"]["fps"] > 0
    assert fake.opened[0].closed
    fake.stall = True
    assert main(["cameras", "--root", str(tmp_path), "--probe"]) == 1  # a camera that gives nothing fails
    assert "probe failed: picamera2:0: no camera frame within 5 s" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("camera", "says"),
    [
        (
            "libcamera",
            "was built without GStreamer, so the pipeline cannot open; on a Raspberry Pi use --camera picamera2",
        ),
        ("picamera2", "sudo apt install python3-picamera2"),
        ("/dev/video99", "/dev/video99: no such device"),
    ],
)
def test_a_tool_given_a_camera_it_cannot_open_says_what_is_missing(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str], camera: str, says: str
) -> None:
    fake_picamera2.hide(monkeypatch)
    argv = ["record", "emu://picar?clock=virtual", "-o", str(tmp_path / "run.mcap"), "--duration", "0.1"]
    assert main([*argv, "--camera", camera]) == 1
    err = capsys.readouterr().err
    assert says in err and err.count("\n") == 1  # one line, no traceback
