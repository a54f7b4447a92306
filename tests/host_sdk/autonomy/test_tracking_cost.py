"""What a frame costs the tracker, counted rather than timed (timings belong to benchmarks/): the
correlation work of a tracking frame, and the homography method of a re-detecting one."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from host_sdk.perception.camera import CameraModel
from host_sdk.perception.tracking import Tracker, TrackState
from tests.support.photo_sequences import SPECS, build

CAMERA = CameraModel.pi_camera_v2(320, 240)


class Counting:
    """OpenCV with its matchTemplate and findHomography calls recorded."""

    def __init__(self, cv2: Any) -> None:
        self._cv2 = cv2
        self.matches: list[tuple[tuple[int, int], tuple[int, int]]] = []
        """(search area h x w, template h x w) per matchTemplate call."""
        self.homography_methods: list[int] = []

    def __getattr__(self, name: str) -> Any:
        return getattr(self._cv2, name)

    def matchTemplate(self, area: np.ndarray, template: np.ndarray, method: int) -> Any:
        self.matches.append((area.shape[:2], template.shape[:2]))
        return self._cv2.matchTemplate(area, template, method)

    def findHomography(self, src: Any, dst: Any, method: int, *args: Any) -> Any:
        self.homography_methods.append(method)
        return self._cv2.findHomography(src, dst, method, *args)


@pytest.fixture(scope="module")
def easy() -> Any:
    return build(next(s for s in SPECS if s.name == "easy"))


def test_a_tracking_frame_searches_its_window_once(easy: Any) -> None:
    """The middle scale scans the search window; the two others only a few pixels round its peak."""
    first = easy.frames[0]
    tracker = Tracker.from_region(first.image, first.box, CAMERA)
    counting = Counting(tracker.cv2)
    tracker.cv2 = counting
    checked = 0
    for frame in easy.frames[1:30]:
        counting.matches.clear()
        track = tracker.update(frame.image, frame.time_s)
        if track.state is not TrackState.TRACKING or len(counting.matches) != 3:
            continue  # the anchored template's second look, or a re-detection: other paths
        (window, tpl), *others = counting.matches
        assert window[0] > tpl[0] + 10 and window[1] > tpl[1] + 10
        for area, t in others:
            assert area[0] <= t[0] + 6 and area[1] <= t[1] + 6, (area, t)
        checked += 1
    assert checked >= 20


def test_a_lost_frame_fits_its_homography_with_usac(easy: Any) -> None:
    """RANSAC runs its 2000 tries on a frame without the object (tens of ms); USAC stops early."""
    import cv2

    first = easy.frames[0]
    tracker = Tracker.from_region(first.image, first.box, CAMERA)
    counting = Counting(tracker.cv2)
    tracker.cv2 = counting
    gone = [f for f in easy.frames if f.box is None]
    assert gone
    for frame in easy.frames[1:]:
        tracker.update(frame.image, frame.time_s)
        if frame is gone[-1]:
            break
    assert counting.homography_methods and set(counting.homography_methods) == {cv2.USAC_DEFAULT}
