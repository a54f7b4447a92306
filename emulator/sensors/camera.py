"""A pinhole camera rendering the 2D scene (numpy + OpenCV), one image column per ray.

Every obstacle is a vertical surface standing on the floor, so a column of the image is a ray in
the plane: the surfaces it crosses, nearest first, each fill the rows between their foot and their
top (`h_cam` above the floor at perpendicular depth z projects to row `cy + fy * h_cam / z`, height
h to `cy - fy * (h - h_cam) / z`). Layers are painted far to near over a chequered floor (0.5 m
tiles, useful texture for optical flow) and a plain upper background. Surfaces are shaded by their
incidence and painted with their pattern (bricks on walls; the target's stripes), then the camera's
optional effects apply: exposure gain, motion blur along the image rows from the yaw rate during the
exposure (cv2.blur), and sensor noise (seeded, so one seed gives one image).

The Pi Camera v2's field of view (62.2 x 48.8 degrees) gives fx ~ fy: square pixels at 4:3.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from emulator.errors import EmulatorValueError
from emulator.world.raycast import F64, Hits, cast
from emulator.world.scene import PATTERNS, Scene
from protocol.errors import import_optional
from protocol.sensors import CameraSpec, Mount

LAYERS = 4
"""Surfaces painted per column (the nearest four; a fifth is almost never visible)."""
SKY = (205, 190, 175)
FLOOR = ((96, 104, 110), (128, 136, 142))
TILE_M = 0.5
LOOKS = ("plain", "photo")
MAX_DISTRACTORS = 8


@dataclass(frozen=True, slots=True)
class CameraOptions:
    width: int = 320
    height: int = 240
    fps: float = 30.0
    noise: float = 2.0
    """Standard deviation of the sensor noise, grey levels (0: none)."""
    exposure: float = 1.0
    """Gain on the image (1: as rendered)."""
    exposure_s: float = 0.01
    """Exposure time, for the motion blur (0: none)."""
    look: str = "plain"
    """plain (flat colours and patterns) or photo (emulator/sensors/photo.py)."""
    distractors: int | None = None
    """Cylinders of the world painted like the target (photo look; None: the look's default)."""

    def __post_init__(self) -> None:
        if self.look not in LOOKS:
            raise EmulatorValueError("camera look", self.look, " or ".join(LOOKS))
        if self.distractors is not None and not 0 <= self.distractors <= MAX_DISTRACTORS:
            raise EmulatorValueError("camera distractors", self.distractors, f"0..{MAX_DISTRACTORS}")


@dataclass(frozen=True, slots=True)
class Layers:
    """The nearest surfaces of every image column, and which of them each pixel shows.

    Per (column, layer), W x k, nearest first: `order` (the surface columns of `hits`), `t`
    (distance along the column's ray, inf: none), `z` (perpendicular depth), `shape` (shape index),
    `u` (position along the surface, metres). Per column: `dirs`, the ray's direction in the
    world (W, 2). Per pixel, H x W: `mask` (the layers covering it, one bit each) and `layer` (the
    nearest of them, -1: none)."""

    k: int
    hits: Hits
    order: NDArray[np.int64]
    t: F64
    z: F64
    shape: NDArray[np.int64]
    u: F64
    dirs: F64
    mask: NDArray[np.int16]
    layer: NDArray[np.int32]
    col_index: NDArray[np.int32]

    def cells(self, layer: NDArray[np.int32]) -> NDArray[np.int64]:
        """Flat indices into (W, k) tables of each pixel's `layer` (any cell where it is -1)."""
        return (self.col_index * self.k + np.maximum(layer, 0)).reshape(-1).astype(np.int64)

    def pixel_shape(self) -> NDArray[np.int64]:
        """(H, W) the shape each pixel shows (meaningless where `layer` is -1)."""
        return np.take(self.shape.reshape(-1), self.cells(self.layer)).reshape(self.layer.shape)


class Renderer:
    def __init__(self, spec: CameraSpec, mount: Mount, options: CameraOptions) -> None:
        self.spec = spec
        self.mount = mount
        self.options = options
        w, h = options.width, options.height
        self.fx = (w / 2) / math.tan(math.radians(spec.hfov_deg) / 2)
        self.fy = (h / 2) / math.tan(math.radians(spec.vfov_deg) / 2)
        self.cx, self.cy = (w - 1) / 2, (h - 1) / 2
        self.col_angle = np.arctan((self.cx - np.arange(w)) / self.fx)
        self.col_cos = np.cos(self.col_angle)
        self.rows = np.arange(h, dtype=np.float64)[:, None]
        self.col_index = np.arange(w, dtype=np.int32)[None, :]
        self.rows32 = (self.cy - np.arange(h)).astype(np.float32)[:, None]
        below = self.rows[:, 0] > self.cy + 0.5
        self.floor_rows = np.nonzero(below)[0]
        self.floor_z = mount.z_m * self.fy / (self.floor_rows - self.cy)
        self.floor_z32 = self.floor_z.astype(np.float32)[:, None]
        self.floor_lateral = ((self.cx - np.arange(w)) / self.fx).astype(np.float32)[None, :]
        self._noise_bank: NDArray[np.float32] | None = None
        self.target_bbox: tuple[int, int, int, int] | None = None
        """Ground truth of the last render: the target's visible pixels as (x0, y0, x1, y1), x1 and
        y1 exclusive; None when it was hidden or out of view."""
        fade = (1.0 / (1.0 + 0.04 * self.floor_z))[:, None, None]
        sky = np.array(SKY, dtype=np.float64)
        self.floor_a = (np.array(FLOOR[0]) * fade + sky * (1 - fade)).astype(np.float32)
        self.floor_b = (np.array(FLOOR[1]) * fade + sky * (1 - fade)).astype(np.float32)
        self.background = np.empty((h, w, 3), dtype=np.float32)
        self.background[:] = np.array(SKY, dtype=np.float32)

    def render(
        self,
        scene: Scene,
        pose: tuple[float, float, float],
        yaw_rate: float,
        rng: np.random.Generator,
        *,
        time_s: float = 0.0,
    ) -> NDArray[np.uint8]:
        """The BGR image the camera sees from the robot pose (x, y, heading) in the world at
        `time_s` (the photo look's lighting changes with it)."""
        cv2 = import_optional("cv2", "vision", "the emulated camera")
        x, y, th = pose
        m = self.mount
        cam_x = x + math.cos(th) * m.x_m - math.sin(th) * m.y_m
        cam_y = y + math.sin(th) * m.x_m + math.cos(th) * m.y_m
        heading = th + m.yaw_rad
        img = np.copy(self.background)
        self._floor(img, scene, cam_x, cam_y, heading)
        self._surfaces(img, scene, cam_x, cam_y, heading)
        opts = self.options
        img = self._expose(img, time_s, rng)
        blur = abs(yaw_rate) * opts.exposure_s * self.fx
        if blur >= 1.5:
            img = np.asarray(cv2.blur(img, (round(blur), 1)), dtype=np.float32)
        if opts.noise > 0:
            img += self._noise(rng)
        return np.clip(img, 0, 255).astype(np.uint8)

    def _expose(self, img: NDArray[np.float32], time_s: float, rng: np.random.Generator) -> NDArray[np.float32]:
        """The fixed gain (the photo look adds lighting drift and auto-exposure)."""
        if self.options.exposure != 1.0:
            img *= self.options.exposure
        return img

    def _noise(self, rng: np.random.Generator) -> NDArray[np.float32]:
        """Luminance noise for one frame: a random window of a bank drawn once (4 frames of
        Gaussian noise), shifted by a random offset per frame, so noise costs no draw per pixel."""
        h, w = self.options.height, self.options.width
        if self._noise_bank is None:
            bank = rng.standard_normal((4 * h, 2 * w), dtype=np.float32) * np.float32(self.options.noise)
            self._noise_bank = bank
        r0, c0 = int(rng.integers(0, 3 * h)), int(rng.integers(0, w))
        return self._noise_bank[r0 : r0 + h, c0 : c0 + w, None]

    def _floor(self, img: NDArray[np.float32], scene: Scene, cam_x: float, cam_y: float, heading: float) -> None:
        z = self.floor_z32
        lateral = self.floor_lateral * z
        c, s = np.float32(math.cos(heading) / TILE_M), np.float32(math.sin(heading) / TILE_M)
        tx = np.floor(np.float32(cam_x / TILE_M) + c * z - s * lateral)
        ty = np.floor(np.float32(cam_y / TILE_M) + s * z + c * lateral)
        odd = ((tx + ty).astype(np.int32) & 1).astype(bool)
        img[self.floor_rows] = np.where(odd[..., None], self.floor_b, self.floor_a)

    def _surfaces(self, img: NDArray[np.float32], scene: Scene, cam_x: float, cam_y: float, heading: float) -> None:
        self.target_bbox = None
        lay = self._layers(scene, cam_x, cam_y, heading, img.shape[0])
        if lay is None:
            return
        valid = lay.layer >= 0
        painted = self._paint(img, scene, lay)
        np.copyto(img, painted, where=valid[..., None])
        if scene.target_index is not None:
            seen = valid & (lay.pixel_shape() == scene.target_index) & self._opaque(lay)
            rows, cols_seen = np.flatnonzero(seen.any(axis=1)), np.flatnonzero(seen.any(axis=0))
            if rows.size:
                self.target_bbox = (int(cols_seen[0]), int(rows[0]), int(cols_seen[-1]) + 1, int(rows[-1]) + 1)

    def _layers(self, scene: Scene, cam_x: float, cam_y: float, heading: float, h: int) -> Layers | None:
        """Which surface each pixel shows: the nearest LAYERS surfaces of every column, and per pixel
        the nearest covering it (None: no surface in the scene)."""
        angles = heading + self.col_angle
        w = angles.shape[0]
        origins = np.tile([cam_x, cam_y], (w, 1))
        dirs = np.column_stack([np.cos(angles), np.sin(angles)])
        hits = cast(scene, origins, dirs)
        if hits.t.shape[1] == 0:
            return None
        k = min(LAYERS, hits.t.shape[1])
        order = np.argsort(hits.t, axis=1)[:, :k]
        cols = np.arange(w)[:, None]
        t = hits.t[cols, order]
        finite = np.isfinite(t)
        z = np.where(finite, t, 1.0) * self.col_cos[:, None]  # (W, k) perpendicular depth
        shape = hits.shape[order]
        h_cam = self.mount.z_m
        top = np.where(finite, self.cy - self.fy * (scene.heights[shape] - h_cam) / z, np.inf)
        bottom = np.where(finite, self.cy + self.fy * h_cam / z, -np.inf)
        # Which layer each pixel shows, the nearest covering it: each layer's rows set its bit in a
        # per-pixel mask (a difference array summed down the columns), the lowest bit wins. Then
        # the pixels are coloured from per-(column, layer) tables: one gather per pixel.
        r0 = np.clip(np.ceil(top), 0, h).astype(np.int64)
        r1 = np.clip(np.floor(bottom) + 1, 0, h).astype(np.int64)
        span = finite & (r1 > r0)
        bits = np.zeros((h + 1, w), dtype=np.int16)
        cj, jj = np.nonzero(span)
        np.add.at(bits, (r0[cj, jj], cj), (1 << jj).astype(np.int16))
        np.add.at(bits, (r1[cj, jj], cj), -(1 << jj).astype(np.int16))
        mask = np.cumsum(bits[:h], axis=0, dtype=np.int16)
        layer = LOWEST_BIT[mask]
        return Layers(k, hits, order, t, z, shape, hits.u[cols, order], dirs, mask, layer, self.col_index)

    def _paint(self, img: NDArray[np.float32], scene: Scene, lay: Layers) -> NDArray[np.float32]:
        """The colour of every pixel's surface (pixels without one: anything)."""
        layer = lay.layer
        cols = np.arange(layer.shape[1])[:, None]
        cell = lay.cells(layer)
        # Patterns from 1 cm texture tiles: the pixel's height above the floor and its position
        # along the surface pick a cell; the table holds both colours of every (column, layer).
        zc = np.take((lay.z / self.fy).astype(np.float32).reshape(-1), cell).reshape(layer.shape)
        height = np.float32(self.mount.z_m) + self.rows32 * zc
        iv = (height * 100).astype(np.int32) % TILE
        iu = (np.take(lay.u.astype(np.float32).reshape(-1), cell) * 100).astype(np.int32) % TILE
        pattern = np.take(self.pattern_of(scene)[lay.shape].reshape(-1), cell)
        alt = TILES[pattern, iv.reshape(-1), iu]
        shade = (0.55 + 0.45 * lay.hits.cos_incidence[cols, lay.order]).astype(np.float32)[..., None, None]
        both = np.stack([self.colour_of(scene)[lay.shape], self.colour2_of(scene)[lay.shape]], axis=2) * shade
        return np.asarray(np.take(both.reshape(-1, 3), cell * 2 + alt, axis=0).reshape(img.shape), dtype=np.float32)

    def _opaque(self, lay: Layers) -> NDArray[np.bool_] | bool:
        """Which target pixels count as seen (the plain look's target is solid)."""
        return True

    def pattern_of(self, scene: Scene) -> NDArray[np.int64]:
        return np.array([PATTERNS.index(s.pattern) for s in scene.shapes], dtype=np.int64)

    def colour_of(self, scene: Scene) -> NDArray[np.float32]:
        return np.array([s.colour for s in scene.shapes], dtype=np.float32)

    def colour2_of(self, scene: Scene) -> NDArray[np.float32]:
        return np.array([s.colour2 for s in scene.shapes], dtype=np.float32)


LOWEST_BIT = np.array([-1] + [(i & -i).bit_length() - 1 for i in range(1, 1 << LAYERS)], dtype=np.int32)
"""The nearest layer (lowest set bit) of each 4-bit coverage mask; -1: no layer."""


def _tiles() -> NDArray[np.int32]:
    """1 cm texture tiles, TILE x TILE (rows: height, columns: along the surface), per pattern:
    1 where a pixel takes the second colour. plain: never; bricks: 8 x 24 cm bricks, 1.2 cm
    mortar, courses offset by half a brick; stripes: 8 cm horizontal bands; checker: 6 cm squares."""
    v = np.arange(TILE)[:, None]
    u = np.arange(TILE)[None, :]
    course = v // 8
    bricks = (v % 8 < 1) | ((u + 12 * (course % 2)) % 24 < 2)
    stripes = (course % 2 == 1) & (u >= 0)
    checker = (v // 6 + u // 6) % 2 == 1
    plain = np.zeros((TILE, TILE), dtype=bool)
    return np.stack([plain, bricks, stripes, checker]).astype(np.int32)


TILE = 48
TILES = _tiles()
"""Indexed by the pattern's number in PATTERNS."""
