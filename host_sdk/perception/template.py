"""Template images for the tracker: read from a file (a PNG with a transparent background is a
cut-out, BGRA) and a cut-out's geometry (the solid middle the search matches, which of its
keypoints lie on the object). OpenCV is imported when a file is read (the `vision` extra)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from host_sdk.errors import CommandRangeError
from host_sdk.extras import require

Image = NDArray[np.uint8]


def read_template(path: str | Path) -> Image:
    """A template image from a file: BGR, or BGRA when the file has transparency (a PNG with the
    background removed: the tracker then matches the object's pixels only; alpha below 128 is
    background). Raises
    CommandRangeError naming the file when it cannot be read as an image."""
    cv2 = require("cv2", "vision", "reading a template")
    image = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
    if image is None:
        raise CommandRangeError("template", str(path), "an image file OpenCV can read (PNG, JPEG, ...)")
    if image.ndim == 3 and image.shape[2] == 4 and int(image[..., 3].min()) < 128:
        if image.dtype == np.uint16:
            image = ((image.astype(np.uint32) + 128) >> 8).clip(0, 255).astype(np.uint8)
        if image.dtype != np.uint8:
            raise CommandRangeError("template", f"{path} ({image.dtype})", "an 8- or 16-bit image")
        return np.ascontiguousarray(image)
    # No transparency: OpenCV's colour read (8-bit BGR, a JPEG's EXIF orientation applied).
    return np.ascontiguousarray(cv2.imread(str(path), cv2.IMREAD_COLOR))


def cutout_core(opaque: NDArray[np.bool_], *, solid: float = 0.9) -> float:
    """The largest share of each side whose central part is at least `solid` object (0.2 at least)."""
    h, w = opaque.shape
    for c in np.arange(1.0, 0.19, -0.05):
        dx, dy = round(w * (1 - c) / 2), round(h * (1 - c) / 2)
        part = opaque[dy : h - dy, dx : w - dx]
        if part.size and float(part.mean()) >= solid:
            return float(round(c, 2))
    return 0.2


def on_cutout(opaque: NDArray[np.bool_], pt: tuple[float, float], f: float) -> bool:
    """A keypoint of the template enlarged by f lies on the cut-out's object."""
    x, y = min(int(pt[0] / f), opaque.shape[1] - 1), min(int(pt[1] / f), opaque.shape[0] - 1)
    return bool(opaque[y, x])
