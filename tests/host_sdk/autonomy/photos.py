"""Real photographs for the person and face detectors' tests (their sources and licences:
tests/data/photos/README.md), and the boxes measured on them by hand."""

from __future__ import annotations

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
    # x, y, w, h: top of the head to the soles, the widest of arms and legs, read off a 20-pixel grid.
    "pedestrians_f050": [(125, 44, 55, 151), (201, 41, 54, 140)],  # walking side by side
    "pedestrians_f525": [(134, 41, 49, 153)],  # standing, facing the camera
    "pedestrians_f650": [(129, 46, 51, 142)],  # walking away
}


def photo(name: str) -> NDArray[np.uint8]:
    """A BGR photo: grace_hopper (matplotlib's sample data, installed with the dev extra) or one of
    tests/data/photos."""
    import cv2

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
