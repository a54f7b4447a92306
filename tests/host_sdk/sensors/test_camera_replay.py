"""Replaying a video file or a folder of images through CameraSource: order, pacing, a clear end."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from host_sdk.sensors import CameraSource, SensorClosedError, SensorOpenError


def shade_of(image: np.ndarray) -> int:  # type: ignore[type-arg]
    return round(float(image.mean()) / 10) * 10


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    for name, shade in (("b.png", 20), ("a.png", 10), ("c.jpg", 30)):
        cv2.imwrite(str(tmp_path / name), np.full((24, 32, 3), shade, np.uint8))
    (tmp_path / "notes.txt").write_text("not an image")
    return tmp_path


def test_a_folder_replays_its_images_in_name_order_then_ends(folder: Path) -> None:
    with CameraSource(str(folder)) as cam:
        frames = [cam.read(), cam.read(), cam.read()]
        assert [shade_of(f.image) for f in frames] == [10, 20, 30]
        assert [f.seq for f in frames] == [1, 2, 3] and frames[0].image.shape == (24, 32, 3)
        assert cam.detail == "replay of 3 images at read speed"
        with pytest.raises(SensorClosedError, match="end of the folder after 3 images"):
            cam.read()


def test_a_folder_paced_by_fps_spaces_the_frames(folder: Path) -> None:
    with CameraSource(f"file://{folder}", fps=20) as cam:
        frames = [cam.read(), cam.read(), cam.read()]
    assert frames[2].time_s - frames[0].time_s >= 2 / 20 - 0.005
    assert [f.device_time_s for f in frames] == pytest.approx([0.0, 0.05, 0.1])
    assert cam.dropped == 0


def test_a_video_file_replays_every_frame_with_its_position(tmp_path: Path) -> None:
    path = tmp_path / "run.avi"
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter.fourcc(*"MJPG"), 10.0, (32, 24))
    assert writer.isOpened()
    for shade in (50, 100, 150, 200):
        writer.write(np.full((24, 32, 3), shade, np.uint8))
    writer.release()
    with CameraSource(str(path), fps=0) as cam:  # as fast as it decodes
        assert cam.fps == pytest.approx(10.0) and "read speed" in cam.detail
        frames = cam.poll() + cam.poll() + cam.poll() + cam.poll()
        assert [shade_of(f.image) for f in frames] == [50, 100, 150, 200]
        assert [f.device_time_s for f in frames] == pytest.approx([0.0, 0.1, 0.2, 0.3])
        with pytest.raises(SensorClosedError, match="end of the video after 4 frames"):
            cam.read()
    with CameraSource(str(path)) as cam:  # without fps: at the video's own rate
        assert cam.detail == "replay of video at 10 fps"
        first, *_, last = [cam.read() for _ in range(4)]
        assert last.time_s - first.time_s >= 0.3 - 0.005


def test_missing_or_empty_replays_say_so(tmp_path: Path) -> None:
    with pytest.raises(SensorOpenError, match="no such file or folder"):
        CameraSource(f"file://{tmp_path}/absent.mp4")
    with pytest.raises(SensorOpenError, match="the folder has no images"):
        CameraSource(str(tmp_path))
