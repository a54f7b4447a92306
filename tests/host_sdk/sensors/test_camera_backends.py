"""CameraSource's routes: picamera2 (against a fake module with its API's shape), V4L2 device
checks, GStreamer only where this OpenCV has it, and errors that name what is missing."""

from __future__ import annotations

import os
import types
from pathlib import Path

import pytest

from host_sdk.extras import MissingDependencyError
from host_sdk.sensors import CameraSource, SensorClosedError, SensorOpenError, SensorTimeoutError
from host_sdk.sensors.camera.pipelines import opencv_build
from host_sdk.sensors.errors import CameraBackendError
from tests.support import fake_picamera2
from tests.support.fake_picamera2 import FIRST_NS, IMX219, PERIOD_NS, USB_WEBCAM

BUILD_INFO = """
  Video I/O:
    DC1394:                      NO
    FFMPEG:                      YES
      avcodec:                   YES (59.37.100)
    GStreamer:                   {gst}
    v4l/v4l2:                    YES (linux/videodev2.h)
"""


def fake_cv2(gstreamer: str) -> types.SimpleNamespace:
    return types.SimpleNamespace(__version__="4.9.0", getBuildInformation=lambda: BUILD_INFO.format(gst=gstreamer))


def test_picamera2_frames_are_bgr_at_the_asked_size_with_sensor_timestamps(monkeypatch: pytest.MonkeyPatch) -> None:
    fake = fake_picamera2.install(monkeypatch, [IMX219])
    with CameraSource("picamera2", width=320, height=240, fps=20) as cam:
        first, second = cam.read(), cam.read(0.5)
        opened = fake.opened[0]
        assert opened.config["main"] == {"size": (320, 240), "format": "RGB888"}
        assert opened.config["controls"] == {"FrameRate": 20.0}
        assert first.image.shape == (240, 320, 3) and first.image[0, 0, 0] == 200  # blue first: BGR
        assert (first.seq, second.seq) == (1, 2) and second.time_s >= first.time_s
        assert first.device_time_s == pytest.approx((FIRST_NS + PERIOD_NS) / 1e9)
        assert second.device_time_s - first.device_time_s == pytest.approx(PERIOD_NS / 1e9)
        assert opened.waits == [1.0, 0.5]  # picamera2's wait: a number is a timeout in seconds
        assert opened.released == opened.captured == 2  # every request went back to libcamera
        assert not cam.queued and cam.fps == 20.0 and "imx219" in cam.detail
    assert opened.closed and not opened.started
    with pytest.raises(SensorClosedError):
        cam.read()


def test_picamera2_index_picks_the_camera_and_a_missing_one_lists_those_present(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    fake = fake_picamera2.install(monkeypatch, [IMX219, USB_WEBCAM])
    with CameraSource("picamera2:1") as cam:
        assert cam.read().image.shape == (480, 640, 3)  # the default size
        assert fake.opened[0].info["Model"] == "uvcvideo" and "(USB)" in cam.detail
    with pytest.raises(SensorOpenError, match=r"picamera2:2: libcamera sees no camera 2 \(cameras: picamera2:0 imx219"):
        CameraSource("picamera2:2")
    fake_picamera2.install(monkeypatch, [])
    with pytest.raises(SensorOpenError, match=r"no camera 0 \(cameras: none\); check the ribbon cable"):
        CameraSource("picamera2")


def test_picamera2_that_delivers_nothing_times_out(monkeypatch: pytest.MonkeyPatch) -> None:
    fake = fake_picamera2.install(monkeypatch, [IMX219])
    with CameraSource("picamera2:0") as cam:
        fake.stall = True
        with pytest.raises(SensorTimeoutError, match=r"picamera2:0: no camera frame within 0\.2 s"):
            cam.read(0.2)


def test_picamera2_missing_says_apt_and_system_site_packages(monkeypatch: pytest.MonkeyPatch) -> None:
    fake_picamera2.hide(monkeypatch)
    with pytest.raises(CameraBackendError) as err:
        CameraSource("picamera2:0")
    assert isinstance(err.value, ImportError) and isinstance(err.value, MissingDependencyError)
    text = str(err.value)
    assert "'picamera2' is not importable" in text
    assert "sudo apt install python3-picamera2" in text and "--system-site-packages" in text


@pytest.mark.parametrize(
    ("source", "named", "fix"),
    [
        ("libcamera", "camera libcamerasrc ! ", "on a Raspberry Pi use --camera picamera2"),
        ("jetson-csi", "camera nvarguscamerasrc sensor-id=0 ! ", "on a Jetson use JetPack's OpenCV"),
        ("videotestsrc ! videoconvert ! appsink", "camera videotestsrc ! ", "sudo apt install python3-opencv"),
    ],
)
def test_pipelines_without_gstreamer_say_what_to_install(
    monkeypatch: pytest.MonkeyPatch, source: str, named: str, fix: str
) -> None:
    import cv2

    monkeypatch.setattr(cv2, "getBuildInformation", lambda: BUILD_INFO.format(gst="NO"))
    with pytest.raises(CameraBackendError) as err:
        CameraSource(source)
    text = str(err.value)
    assert "was built without GStreamer" in text and fix in text and "--system-site-packages" in text
    assert text.startswith(named)


def test_opencv_build_reads_gstreamer_and_ffmpeg() -> None:
    assert opencv_build(fake_cv2("NO")).gstreamer is False
    with_gst = opencv_build(fake_cv2("YES (1.20.3)"))
    assert with_gst.gstreamer and with_gst.ffmpeg and with_gst.v4l2 and with_gst.version == "4.9.0"


def test_v4l2_device_missing_or_not_readable_names_the_fix(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    with pytest.raises(SensorOpenError, match=r"/dev/video99: no such device .*roverlink cameras"):
        CameraSource("/dev/video99")
    with pytest.raises(SensorOpenError, match=r"/dev/video98: no such device"):
        CameraSource(98)
    with pytest.raises(SensorOpenError, match=r"/dev/v4l/by-id/usb-cam-video-index0: no such device"):
        CameraSource("/dev/v4l/by-id/usb-cam-video-index0")  # udev's stable name for a webcam
    from host_sdk.sensors.camera import opencv

    node = tmp_path / "video0"
    node.write_bytes(b"")
    real_access = os.access
    monkeypatch.setattr(os, "access", lambda p, mode: False if str(p) == str(node) else real_access(p, mode))
    with pytest.raises(
        SensorOpenError, match="exists but is not readable by this user: add yourself to the video group"
    ):
        opencv.check_device(str(node))


def test_an_unknown_source_lists_the_forms() -> None:
    with pytest.raises(SensorOpenError, match="not a source this can open, nor an existing file: picamera2"):
        CameraSource("webcam-please")
