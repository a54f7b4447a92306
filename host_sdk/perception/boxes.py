"""Small geometry on image boxes (x, y, w, h) and correlation maps that the tracker uses."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Box = tuple[float, float, float, float]
"""x, y (top-left), width, height in pixels."""
Image = NDArray[np.uint8]


def in_ellipse(pt: tuple[float, float], shape: tuple[int, ...]) -> bool:
    """Inside the ellipse inscribed in an image of `shape` (where a selected object is)."""
    h, w = shape[:2]
    return ((pt[0] - w / 2) / (w / 2)) ** 2 + ((pt[1] - h / 2) / (h / 2)) ** 2 <= 0.8


def visible_share(box: Box, image: Image) -> float:
    """Share of the box inside the image."""
    H, W = image.shape[:2]
    x, y, w, h = box
    iw = max(0.0, min(x + w, W) - max(x, 0.0))
    ih = max(0.0, min(y + h, H) - max(y, 0.0))
    return float(iw * ih / max(w * h, 1e-9))


def near_same(a: Box, b: Box) -> bool:
    """Two boxes within a few pixels of each other (a candidate already judged)."""
    return all(abs(u - v) <= 3.0 for u, v in zip(a, b, strict=True))


def centre(box: Box) -> tuple[float, float]:
    """The box's centre."""
    return box[0] + box[2] / 2, box[1] + box[3] / 2


def subpixel_peak(res: NDArray[np.float32], loc: tuple[int, int]) -> tuple[float, float]:
    """Parabola through the peak and its neighbours, per axis (a quarter-pixel better than the grid)."""
    x, y = loc
    h, w = res.shape
    dx = dy = 0.0
    if 0 < x < w - 1:
        a, b, c = float(res[y, x - 1]), float(res[y, x]), float(res[y, x + 1])
        den = a - 2 * b + c
        dx = 0.5 * (a - c) / den if den < 0 else 0.0
    if 0 < y < h - 1:
        a, b, c = float(res[y - 1, x]), float(res[y, x]), float(res[y + 1, x])
        den = a - 2 * b + c
        dy = 0.5 * (a - c) / den if den < 0 else 0.0
    return dx, dy
