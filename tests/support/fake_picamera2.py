"""A stand-in for the `picamera2` module with its API's shape (Picamera2(camera_num),
global_camera_info(), create_video_configuration, configure, start, capture_request(wait=) whose
request has make_array/get_metadata/release, stop, close), installed in sys.modules by a test.

    fake = install(monkeypatch, cameras=[IMX219])
    ...CameraSource("picamera2:0")...
    assert fake.opened[0].released == fake.opened[0].captured
"""

from __future__ import annotations

import sys
import types
from typing import Any, ClassVar

import numpy as np
import pytest

IMX219 = {"Model": "imx219", "Location": 2, "Rotation": 180, "Id": "/base/soc/i2c0mux/i2c@1/imx219@10", "Num": 0}
USB_WEBCAM = {"Model": "uvcvideo", "Id": "/base/soc/usb@7e980000-1.3:1.0-046d:0825", "Num": 1}
PERIOD_NS = 33_333_333
FIRST_NS = 5_000_000_000


class FakeRequest:
    def __init__(self, camera: FakePicamera2, image: np.ndarray[Any, Any], stamp_ns: int) -> None:
        self.camera = camera
        self.image = image
        self.stamp_ns = stamp_ns

    def make_array(self, name: str) -> np.ndarray[Any, Any]:
        assert name == "main"
        return self.image

    def get_metadata(self) -> dict[str, Any]:
        return {"SensorTimestamp": self.stamp_ns, "ExposureTime": 10000, "FrameDuration": PERIOD_NS // 1000}

    def release(self) -> None:
        self.camera.released += 1


class FakePicamera2:
    cameras: ClassVar[list[dict[str, Any]]] = []
    opened: ClassVar[list[FakePicamera2]] = []
    stall = False
    """capture_request raises TimeoutError (the camera delivers nothing)."""

    @staticmethod
    def global_camera_info() -> list[dict[str, Any]]:
        return [dict(c) for c in FakePicamera2.cameras]

    def __init__(self, camera_num: int = 0) -> None:
        # as picamera2 does: the index is a position in global_camera_info()
        self.info = self.global_camera_info()[camera_num]
        self.config: dict[str, Any] = {}
        self.started = self.closed = False
        self.captured = self.released = 0
        self.waits: list[Any] = []
        FakePicamera2.opened.append(self)

    def create_video_configuration(
        self, main: dict[str, Any] | None = None, controls: dict[str, Any] | None = None, **kwargs: Any
    ) -> dict[str, Any]:
        return {"main": {"size": (1280, 720), "format": "XBGR8888", **(main or {})}, "controls": dict(controls or {})}

    def configure(self, config: dict[str, Any]) -> None:
        self.config = config

    def start(self) -> None:
        assert self.config, "configure before start"
        self.started = True

    def capture_request(self, wait: Any = None) -> FakeRequest:
        assert self.started
        self.waits.append(wait)
        if FakePicamera2.stall:
            raise TimeoutError("timed out")
        self.captured += 1
        w, h = self.config["main"]["size"]
        image = np.zeros((h, w, 3), np.uint8)
        image[..., 0] = 200  # B first: RGB888 is BGR in memory
        image[0, 0, 1] = self.captured % 256
        return FakeRequest(self, image, FIRST_NS + self.captured * PERIOD_NS)

    def stop(self) -> None:
        self.started = False

    def close(self) -> None:
        self.closed = True


def install(monkeypatch: pytest.MonkeyPatch, cameras: list[dict[str, Any]]) -> type[FakePicamera2]:
    module = types.ModuleType("picamera2")
    module.Picamera2 = FakePicamera2  # type: ignore[attr-defined]
    monkeypatch.setattr(FakePicamera2, "cameras", list(cameras))
    monkeypatch.setattr(FakePicamera2, "opened", [])
    monkeypatch.setattr(FakePicamera2, "stall", False)
    monkeypatch.setitem(sys.modules, "picamera2", module)
    return FakePicamera2


def hide(monkeypatch: pytest.MonkeyPatch) -> None:
    """Make `import picamera2` fail, as on a machine without it."""
    monkeypatch.setitem(sys.modules, "picamera2", None)
