"""The distribution's camera stack kept intact (docs/sensors.md#cameras): RoverLink in a venv made
with --system-site-packages from the system's own Python, without the vision extra, reads a
GStreamer pipeline through the distribution's OpenCV, and the system's numpy and cv2 are the ones
imported. scripts/test_system_opencv.sh makes that venv (.venv-system, from /usr/bin/python3 with
Debian's python3-opencv and gstreamer1.0-plugins-base) and runs this file in it with
ROVERLINK_REQUIRE_SYSTEM_OPENCV=1; elsewhere (a pip OpenCV without GStreamer) it is skipped.
"""

from __future__ import annotations

import importlib.metadata
import os
import subprocess
import sys
from pathlib import Path

import pytest

from host_sdk.sensors.camera import CameraSource
from host_sdk.sensors.camera.pipelines import opencv_build
from protocol.numpy_abi import SYSTEM_PREFIX

REQUIRE = os.environ.get("ROVERLINK_REQUIRE_SYSTEM_OPENCV") == "1"
PIPELINE = (
    "videotestsrc is-live=true pattern=ball ! video/x-raw, width=320, height=240, framerate=30/1 ! "
    "videoconvert ! video/x-raw, format=BGR ! appsink drop=1 max-buffers=2"
)


def _system_opencv() -> str | None:
    """Why the distribution's OpenCV with GStreamer is not what this interpreter imports (None: it is)."""
    try:
        import cv2
    except ImportError as exc:
        return f"no cv2 ({exc})"
    where = str(getattr(cv2, "__file__", ""))
    if not where.startswith(SYSTEM_PREFIX):
        return f"cv2 is not the distribution's ({where})"
    if not opencv_build(cv2).gstreamer:
        return "this OpenCV has no GStreamer"
    return None


PROBLEM = _system_opencv()
if PROBLEM is not None:
    reason = f"the distribution's OpenCV route: {PROBLEM}; run bash scripts/test_system_opencv.sh"
    if REQUIRE:
        pytest.fail(reason, pytrace=False)
    pytest.skip(reason, allow_module_level=True)


def _dpkg_version(package: str) -> str:
    out = subprocess.run(["dpkg-query", "-W", "-f=${Version}", package], capture_output=True, text=True, check=True)
    return out.stdout


def test_the_venv_imports_the_systems_numpy_and_opencv_and_no_wheel_of_either() -> None:
    import cv2
    import numpy

    assert sys.prefix != sys.base_prefix, "not in a venv"
    assert numpy.__file__.startswith(SYSTEM_PREFIX) and cv2.__file__.startswith(SYSTEM_PREFIX)
    assert numpy.__version__ in _dpkg_version("python3-numpy")  # e.g. 1:1.24.2-1+deb12u1
    assert cv2.__version__.split("-")[0] in _dpkg_version("python3-opencv")
    venv = Path(sys.prefix)
    wheels = [
        d.metadata["Name"] for d in importlib.metadata.distributions() if venv in Path(str(d.locate_file(""))).parents
    ]
    assert not {"numpy", "opencv-python", "opencv-python-headless", "opencv-contrib-python"} & {
        w.lower() for w in wheels
    }
    assert "roverlink" in {w.lower() for w in wheels}


def test_camera_source_reads_a_gstreamer_pipeline_through_the_systems_opencv() -> None:
    with CameraSource(PIPELINE) as cam:
        frames = [cam.read(timeout_s=5.0) for _ in range(10)]
        assert cam.detail.startswith("GStreamer pipeline")
    assert [f.seq for f in frames] == list(range(1, 11))
    assert all(f.image.shape == (240, 320, 3) for f in frames)
    times = [f.time_s for f in frames]
    assert times == sorted(times)
    assert any(int(f.image.max()) > 0 for f in frames)  # the ball, not a black picture


def test_roverlink_record_writes_the_pipelines_frames(tmp_path: Path) -> None:
    from mcap.reader import make_reader

    from host_sdk.recording.schemas import TOPIC_IMAGE

    path = tmp_path / "run.mcap"
    command = [sys.executable, "-m", "roverlink", "record", "emu://picar", "--camera", PIPELINE]
    command += ["-o", str(path), "--duration", "1.5"]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "with the camera" in done.stdout
    with path.open("rb") as f:
        images = [m for _, channel, m in make_reader(f).iter_messages() if channel.topic == TOPIC_IMAGE]
    assert len(images) >= 10  # about 45 at 30 fps; the board's own feedback shares the CPU


def test_a_pip_numpy_over_the_systems_opencv_is_one_line_naming_cv2_numpy_and_the_fix() -> None:
    """As with picamera2 (its issues 1088 and 1211): a numpy 2 from pip in front of the system's."""
    python = os.environ.get("ROVERLINK_NUMPY2_PYTHON")
    if not python:
        if REQUIRE:
            pytest.fail("ROVERLINK_NUMPY2_PYTHON is not set (scripts/test_system_opencv.sh sets it)", pytrace=False)
        pytest.skip("ROVERLINK_NUMPY2_PYTHON: a venv like this one with a pip numpy 2 (scripts/test_system_opencv.sh)")
    code = "from roverlink.cli import main; raise SystemExit(main(['cameras']))"
    done = subprocess.run([python, "-c", code], capture_output=True, text=True, timeout=120, check=False)
    line = next((ln for ln in done.stdout.splitlines() if ln.startswith("OpenCV:")), "")
    assert line.startswith(f"OpenCV: cv2 ({SYSTEM_PREFIX}") and " cannot be loaded with numpy 2." in line, done.stdout
    assert "`pip uninstall numpy` in this environment" in line
    assert "_ARRAY_API" not in done.stderr and "NumPy 1.x" not in done.stderr  # numpy's banner kept back
