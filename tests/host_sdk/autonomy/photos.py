"""Real photographs for the person and face detectors' tests (their sources and licences:
tests/data/photos/README.md), and the boxes measured on them by hand."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray

PHOTOS = Path(__file__).resolve().parents[2] / "data" / "photos"

FACES: dict[str, tuple[float, float, float, float]] = {
    # x, y, w, h: forehead (below the hair or the cap's brim) to chin, cheek to cheek, read off a
    # 10-pixel grid drawn over each photo.
    "grace_hopper": (170, 135, 195, 175),
    "astronaut_collins": (187, 75, 73, 103),
}

PERSONS: dict[str, list[tuple[float, float, float, float]]] = {
    # x, y, w, h: top of the head to the soles, the widest of arms and legs, read off a 20-pixel grid
    # drawn over each crop (CROPS).
    "pedestrians_f050": [(125, 44, 55, 151), (201, 41, 54, 140)],  # walking side by side
    "pedestrians_f525": [(134, 41, 49, 153)],  # standing, facing the camera
    "pedestrians_f650": [(129, 46, 51, 142)],  # walking away
}


VTEST = Path("/usr/share/doc/opencv-doc/examples/data/vtest.avi")
"""OpenCV's sample street-camera clip, from Debian's opencv-doc (scripts/test.sh installs it): read
where it is installed, not copied into this repository (tests/data/photos/README.md)."""
CROPS = {"pedestrians_f050": (50, 428, 189), "pedestrians_f525": (525, 548, 245), "pedestrians_f650": (650, 388, 197)}
"""Frame, left, top of a 200 x 150 crop, enlarged to 320 x 240: people as a robot's camera a few
metres away would see them."""


@cache
def _vtest_frames() -> dict[int, NDArray[np.uint8]]:
    import cv2

    if not VTEST.is_file():
        raise FileNotFoundError(
            f"{VTEST}: the pedestrian photos come from Debian's opencv-doc (apt-get install opencv-doc)"
        )
    wanted, frames = {f for f, _, _ in CROPS.values()}, {}
    capture = cv2.VideoCapture(str(VTEST))
    try:
        for i in range(max(wanted) + 1):
            ok, frame = capture.read()
            assert ok, f"{VTEST}: frame {i} unreadable"
            if i in wanted:
                frames[i] = np.asarray(frame, dtype=np.uint8)
    finally:
        capture.release()
    return frames


def _pedestrians(name: str) -> NDArray[np.uint8]:
    import cv2

    index, x, y = CROPS[name]
    crop = _vtest_frames()[index][y : y + 150, x : x + 200]
    return np.asarray(cv2.resize(crop, (320, 240), interpolation=cv2.INTER_CUBIC), dtype=np.uint8)


def photo(name: str) -> NDArray[np.uint8]:
    """A BGR photo: grace_hopper (matplotlib's sample data, installed with the dev extra), a crop of
    OpenCV's street-camera clip (`pedestrians_*`, Debian's opencv-doc) or one of tests/data/photos."""
    import cv2

    if name in CROPS:
        return _pedestrians(name)
    if name == "grace_hopper":
        from matplotlib import cbook

        path = str(cbook.get_sample_data("grace_hopper.jpg", asfileobj=False))
    else:
        path = str(PHOTOS / f"{name}.jpg")
    image = cv2.imread(path, cv2.IMREAD_COLOR)
    assert image is not None, path
    return np.asarray(image, dtype=np.uint8)


def _opencv_has_detectors() -> bool:
    import cv2

    return hasattr(cv2, "HOGDescriptor") and hasattr(cv2, "CascadeClassifier")


needs_detectors = pytest.mark.skipif(
    not _opencv_has_detectors(),
    reason="this OpenCV has no HOG or Haar cascades (OpenCV 5 moved them to contrib; the vision and dev "
    "extras ask for <5): test_the_installed_opencv_has_the_detectors fails for it",
)
