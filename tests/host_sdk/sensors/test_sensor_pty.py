"""`roverlink emulate` serving the sensors on real ptys and HTTP; the SDK's drivers read them (as
they read the real devices) and agree with the world the emulator was given."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from collections.abc import Callable, Iterator
from contextlib import AbstractContextManager
from typing import Any, TypeVar

import pytest
from sensor_truth import agreement

from emulator.world import load_world
from host_sdk import TransportError
from host_sdk.sensors import CameraSource, Jy901, Lidar
from host_sdk.transport import SerialTransport, open_transport
from protocol.generated.profiles import ROBOT_SENSORS
from tests.support.emulate import ROOM, SENSOR_ROBOT_ARGS, emulate
from tests.support.wait import wait_until

P = TypeVar("P")


@pytest.fixture(scope="module")
def served() -> Iterator[dict[str, list[str]]]:
    args = SENSOR_ROBOT_ARGS
    with emulate(*args, devices=3, clean_exit=True) as served:
        yield {"board": [served.url], **served.devices}


def test_stdout_names_each_device_then_its_port(served: dict[str, list[str]]) -> None:
    assert served["board"][0].startswith("/dev/")
    assert served["lidar"][:2] == ["lidar", "rplidar-a1"] and served["lidar"][-1].startswith("/dev/")
    assert served["imu"][:2] == ["imu", "jy901"] and served["imu"][-1].startswith("/dev/")
    assert served["camera"][:2] == ["camera", "pi-camera-v2"]
    assert served["camera"][-1].startswith("http://127.0.0.1:")


def test_lidar_over_a_pty_agrees_with_the_scene(served: dict[str, list[str]]) -> None:
    scene = load_world(ROOM)
    mount = ROBOT_SENSORS["diffdrive-bts7960"].mount("lidar")
    assert mount is not None
    with Lidar.open(served["lidar"][-1], "rplidar-a1") as lidar:
        info = lidar.info()
        assert info.model == 0x18 and info.firmware == (1, 29)
        lidar.start()
        scan = lidar.read_scan(timeout_s=5.0)
        lidar.stop()
    assert 300 < len(scan) < 420  # ~364 points at 5.5 Hz
    # The board was never opened: the robot stands at the start. The target moves, so it may
    # disagree with a scene frozen at t = 0 for the few points that see it.
    assert agreement(scan, scene, scene.start, mount) > 0.9


def test_the_lidar_reads_through_the_boards_transport(served: dict[str, list[str]]) -> None:
    with Lidar.open(served["lidar"][-1], "rplidar-a1") as lidar, open_transport(served["board"][0]) as board:
        assert type(lidar.port) is type(board) is SerialTransport
        assert lidar.info().model == 0x18  # read through it


def _unplugged_error(open_port: Callable[[str], AbstractContextManager[P]], read: Callable[[P], object]) -> str:
    """The TransportError text a port gives once its device goes away (the path made generic)."""
    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)
    with open_port(path) as port:
        os.close(master)
        with pytest.raises(TransportError) as caught:
            read(port)
    return str(caught.value).replace(path, "PORT")


def test_a_sensor_port_fails_in_the_boards_words() -> None:
    lidar_error = _unplugged_error(lambda path: Lidar.open(path, "rplidar-a1"), lambda lidar: lidar.poll(1.0))
    board_error = _unplugged_error(open_transport, lambda board: board.read(1.0))
    assert lidar_error == board_error
    assert board_error.startswith("reading PORT failed: ")
    missing = "/nonexistent/ttyUSB9"
    with pytest.raises(TransportError) as from_lidar:
        Lidar.open(missing, "rplidar-a1")  # 115200 baud, the board's default
    with pytest.raises(TransportError) as from_board:
        open_transport(missing)
    assert str(from_lidar.value) == str(from_board.value)
    assert "there is no such device" in str(from_board.value)


def test_imu_over_a_pty_reports_the_heading_within_its_bias(served: dict[str, list[str]]) -> None:
    with Jy901.open(served["imu"][-1]) as imu:
        sample = imu.read(timeout_s=3.0)
    assert sample.angle is not None and sample.accel is not None
    assert abs((sample.angle[2] - 0.0 + math.pi) % (2 * math.pi) - math.pi) < 0.2  # start heading 0
    assert sample.accel[2] == pytest.approx(9.81, abs=0.3)


def test_cv2_videocapture_opens_the_camera_url_unchanged(served: dict[str, list[str]]) -> None:
    import cv2

    url = served["camera"][-1]
    cap = cv2.VideoCapture(url)
    try:
        assert cap.isOpened()

        def frame() -> list[Any] | None:
            ok, image = cap.read()
            return [image] if ok else None

        (image,) = wait_until(frame, 10, "a frame from cv2.VideoCapture", poll_s=0)
        assert image.shape == (240, 320, 3)
    finally:
        cap.release()
    with CameraSource(url) as cam:  # the SDK's own MJPEG reader: the emulator's headers are kept
        frame, after = cam.read(5.0), cam.read(5.0)
        assert cam.detail == "HTTP MJPEG stream"
    assert frame.image.shape == (240, 320, 3) and frame.seq == 1
    assert frame.device_time_s is not None and after.device_time_s is not None
    assert after.device_time_s > frame.device_time_s and frame.jpeg is not None


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--lidar", "rplidar-a1", "--lidar-hz", "25"], "lidar scan_hz = 25.0 is not allowed: 1..10 Hz"),
        (["--world", "/nonexistent/room.toml"], "world = '/nonexistent/room.toml' is not allowed"),
        (["--world", "random:x"], "random:SEED with SEED a whole number"),
        (["--camera", "100x100"], "camera size = '100x100' is not allowed: 320x240 or 640x480"),
        (["--camera-port", "70000"], "argument --camera-port: '70000' is not allowed: an integer in 0..65535"),
        (["--backend", "simavr", "--imu", "jy901"], "need --backend python"),
        (["--backend", "simavr", "--truth", "/tmp/t.jsonl"], "need --backend python"),
        (
            ["--imu", "jy901", "--truth", "/tmp/t.jsonl"],
            "--truth records when the lidar passes its rear: it needs --lidar",
        ),
    ],
)
def test_bad_sensor_options_exit_2_and_say_why(args: list[str], message: str) -> None:
    out = subprocess.run(
        [sys.executable, "-m", "roverlink", "emulate", *args], check=False, capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 2
    assert message in out.stderr
    assert out.stdout == ""
