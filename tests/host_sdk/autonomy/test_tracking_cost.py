"""What a frame costs the tracker, counted rather than timed (timings belong to benchmarks/): the
correlation work of a tracking frame, and the homography method of a re-detecting one."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from host_sdk.body import CameraModel
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


@pytest.mark.parametrize("scale", [0.16, 0.2, 0.5])
def test_a_far_object_is_found_again_at_its_size(scale: float) -> None:
    """Re-detection works on a reduced frame; an object a few pixels across is still matched at
    full size, not lost or boxed at the wrong size (a template taken at 0.8 m, the object at 5 m)."""
    import cv2

    rng = np.random.default_rng(3)
    template = np.zeros((80, 48, 3), np.uint8)
    for i, colour in enumerate([(40, 40, 220), (40, 200, 230), (200, 60, 40), (40, 40, 220)]):
        template[i * 20 : (i + 1) * 20] = colour  # bands, as the emulator's targets
    scene = cv2.resize(build(SPECS[0]).frames[0].image, (320, 240))
    frame = scene.copy()
    h, w = round(80 * scale), round(48 * scale)
    x, y = 201, 97
    frame[y : y + h, x : x + w] = cv2.resize(template, (w, h), interpolation=cv2.INTER_AREA)
    frame = np.clip(frame + rng.normal(0, 2, frame.shape), 0, 255).astype(np.uint8)
    track = Tracker(template, CAMERA).detect(frame, 0.0)
    assert track.found and track.box is not None
    bx, by, bw, bh = track.box
    assert abs(bx + bw / 2 - (x + w / 2)) <= 2 and abs(by + bh / 2 - (y + h / 2)) <= 2, track.box
    assert bh == pytest.approx(h, rel=0.15), track.box
