"""Vectorised ray casting against a Scene: K rays against every segment and circle at once.

A ray is an origin and a unit direction. `cast` returns, for every ray and every surface, the
distance to the hit (inf when it misses), so a lidar takes the minimum and the camera the nearest
few in order. The arrays are K x (segments + circles): a 360-ray lidar batch against a 60-segment
room is 22k cells, cheap for numpy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from emulator.world.scene import Scene

F64 = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class Hits:
    """Every ray against every surface: columns are the scene's segments, then its circles."""

    t: F64
    """(K, S) distance along each ray to each surface (inf: no hit)."""
    shape: NDArray[np.int64]
    """(S,) shape index of each surface column."""
    cos_incidence: F64
    """(K, S) |cos| of the angle between the ray and the surface normal (1: head on)."""
    u: F64
    """(K, S) position along the surface of the hit, in metres (for textures)."""


def cast(scene: Scene, origins: F64, dirs: F64) -> Hits:
    """Distances from each ray (origins (K, 2), unit dirs (K, 2)) to every surface of `scene`."""
    seg_t, seg_cos, seg_u = _segments(scene.segments, origins, dirs)
    cir_t, cir_cos, cir_u = _circles(scene.circles, origins, dirs)
    return Hits(
        t=np.concatenate([seg_t, cir_t], axis=1),
        shape=np.concatenate([scene.segment_shape, scene.circle_shape]),
        cos_incidence=np.concatenate([seg_cos, cir_cos], axis=1),
        u=np.concatenate([seg_u, cir_u], axis=1),
    )


def nearest(scene: Scene, origins: F64, dirs: F64) -> tuple[F64, NDArray[np.int64], F64]:
    """(distance, shape index or -1, |cos incidence|) of the first surface each ray hits."""
    hits = cast(scene, origins, dirs)
    k = np.arange(hits.t.shape[0])
    if hits.t.shape[1] == 0:
        return np.full(k.shape, np.inf), np.full(k.shape, -1, dtype=np.int64), np.zeros(k.shape)
    col = np.argmin(hits.t, axis=1)
    t = hits.t[k, col]
    shape = np.where(np.isfinite(t), hits.shape[col], -1)
    return t, shape, hits.cos_incidence[k, col]


def _segments(seg: F64, o: F64, d: F64) -> tuple[F64, F64, F64]:
    """Ray-segment intersections: o + t d = p + s e with t > 0 and 0 <= s <= 1."""
    if seg.shape[0] == 0:
        empty = np.zeros((o.shape[0], 0))
        return empty, empty, empty
    px, py = seg[:, 0], seg[:, 1]
    ex, ey = seg[:, 2] - px, seg[:, 3] - py
    dx, dy = d[:, 0:1], d[:, 1:2]
    wx, wy = px - o[:, 0:1], py - o[:, 1:2]
    denom = dx * ey - dy * ex
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (wx * ey - wy * ex) / denom
        s = (wx * dy - wy * dx) / denom
    ok = (np.abs(denom) > 1e-12) & (t > 1e-9) & (s >= 0.0) & (s <= 1.0)
    length = np.hypot(ex, ey)
    cos = np.abs(denom) / np.maximum(length, 1e-12)
    return np.where(ok, t, np.inf), np.where(ok, cos, 0.0), np.where(ok, s * length, 0.0)


def _circles(cir: F64, o: F64, d: F64) -> tuple[F64, F64, F64]:
    """Ray-circle intersections from outside: the nearer root of |o + t d - c| = r."""
    if cir.shape[0] == 0:
        empty = np.zeros((o.shape[0], 0))
        return empty, empty, empty
    cx, cy, r = cir[:, 0], cir[:, 1], cir[:, 2]
    fx, fy = o[:, 0:1] - cx, o[:, 1:2] - cy
    b = fx * d[:, 0:1] + fy * d[:, 1:2]
    c = fx * fx + fy * fy - r * r
    disc = b * b - c
    root = np.sqrt(np.maximum(disc, 0.0))
    t = -b - root
    ok = (disc > 0) & (t > 1e-9) & (c > 0)
    hx = fx + t * d[:, 0:1]
    hy = fy + t * d[:, 1:2]
    rr = np.maximum(r, 1e-12)
    cos = np.abs(hx * d[:, 0:1] + hy * d[:, 1:2]) / rr
    u = (np.arctan2(hy, hx) + np.pi) * rr
    return np.where(ok, t, np.inf), np.where(ok, cos, 0.0), np.where(ok, u, 0.0)


def clearance(scene: Scene, x: float, y: float, radius: float, *, skip_shape: int | None = None) -> tuple[float, int]:
    """(signed gap between a disc at (x, y) and the nearest surface, that surface's shape); a
    negative gap is an overlap. `skip_shape` leaves one shape out."""
    best, best_shape = np.inf, -1
    seg = scene.segments
    if seg.shape[0]:
        px, py = seg[:, 0], seg[:, 1]
        ex, ey = seg[:, 2] - px, seg[:, 3] - py
        ll = np.maximum(ex * ex + ey * ey, 1e-18)
        s = np.clip(((x - px) * ex + (y - py) * ey) / ll, 0.0, 1.0)
        gap = np.hypot(px + s * ex - x, py + s * ey - y) - radius
        if skip_shape is not None:
            gap = np.where(scene.segment_shape == skip_shape, np.inf, gap)
        i = int(np.argmin(gap))
        best, best_shape = float(gap[i]), int(scene.segment_shape[i])
    cir = scene.circles
    if cir.shape[0]:
        gap = np.hypot(cir[:, 0] - x, cir[:, 1] - y) - cir[:, 2] - radius
        if skip_shape is not None:
            gap = np.where(scene.circle_shape == skip_shape, np.inf, gap)
        i = int(np.argmin(gap))
        if gap[i] < best:
            best, best_shape = float(gap[i]), int(scene.circle_shape[i])
    return best, best_shape
