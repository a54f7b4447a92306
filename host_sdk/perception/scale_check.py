"""The scale check: the size at which the object's first template fits a tracked box best.

The tracking search (tracking.py) tries three sizes a few per cent apart round its prediction: the
box follows an object that nears or recedes, but nothing tells it that the box is the wrong size. A
plain object's parts correlate almost as well as all of it (a cup's rim and side look like a smaller
cup), so a box that landed on a part (re-detected while a pole still hid the rest, or shrunk under
it) stays there, and the adaptive template learns the part. The check correlates the first template
(which never learns) at a wider ladder of sizes centred on the box, and moves the box to the size
that fits best, if it fits clearly better than the box's own.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from host_sdk.perception.appearance import Appearance

Image = NDArray[np.uint8]
Box = tuple[float, float, float, float]

SLACK_PX = 2
"""How far (pixels, at the matching's reduced size) each size's centre may move from the box's."""


def best_size(
    cv2: Any, look: Appearance, image: Image, box: Box, scales: Sequence[float], *, work_px: int, margin: float
) -> Box:
    """`box` resized by the one of `scales` (1.0 among them: its own size) whose first template's
    core correlates best round its centre, if that beats its own size's by `margin`; else `box`.
    The box's neighbourhood is reduced so the core is about `work_px` across, as tracking does."""
    x, y, w, h = box
    cx, cy = x + w / 2, y + h / 2
    core = look.core
    f = min(1.0, work_px / (max(w, h) * core))
    r = SLACK_PX
    top = max(scales)
    hw, hh = w * top * core / 2 + (r + 2) / f, h * top * core / 2 + (r + 2) / f
    H, W = image.shape[:2]
    x0, y0 = max(0, int(cx - hw)), max(0, int(cy - hh))
    x1, y1 = min(W, math.ceil(cx + hw)), min(H, math.ceil(cy + hh))
    if x1 - x0 < 8 or y1 - y0 < 8:
        return box
    window = image[y0:y1, x0:x1]
    if f < 1.0:
        window = cv2.resize(window, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)
    space = look.space(window)
    ccx, ccy = (cx - x0) * f, (cy - y0) * f
    own: float | None = None
    best: tuple[float, Box] | None = None
    for s in sorted(scales):
        tw, th = round(w * s * core * f), round(h * s * core * f)
        ax, ay = round(ccx - tw / 2) - r, round(ccy - th / 2) - r
        if tw < 4 or th < 4 or ax < 0 or ay < 0 or ax + tw + 2 * r > space.shape[1] or ay + th + 2 * r > space.shape[0]:
            continue  # too small to say, or past the picture's edge
        area = space[ay : ay + th + 2 * r, ax : ax + tw + 2 * r]
        res = cv2.matchTemplate(area, look.template(tw, th, anchor=True), cv2.TM_CCOEFF_NORMED)
        _, score, _, loc = cv2.minMaxLoc(res)
        if s == 1.0:
            own = float(score)
        elif best is None or score > best[0]:
            bw, bh = tw / f / core, th / f / core
            bx = (ax + loc[0] + tw / 2) / f + x0 - bw / 2
            by = (ay + loc[1] + th / 2) / f + y0 - bh / 2
            best = (float(score), (bx, by, bw, bh))
    if best is None or own is None or best[0] < own + margin:
        return box
    return best[1]
