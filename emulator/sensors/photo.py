"""The camera's photo look (`look=photo`): the plain look's geometry as a photograph shows it.

A tracker tuned on flat colours, where the target fills its box exactly, collapses on real images;
this look keeps the plain look's ray casting (camera.py: which surface each pixel shows) and paints:

- textures: photographs (brick walls, a gravel floor, grass on cylinders, textures/README.md) and a
  procedural cardboard on boxes (textures.py), placed by the position along the surface (`u`) and
  the height on walls, by the floor point each pixel sees (perspective-correct) on the floor;
- light: one directional light per world (its azimuth from the world's name), Lambert shading by
  each surface's normal, so walls facing away from it are dark; contact shadows on the floor near
  every obstacle and under the target;
- the target: a cut-out figure (head, shoulders, body) with a soft alpha edge on its cylinder, in
  the target's striped colours woven with a fine texture; outside the figure the pixel shows what is
  behind, so the target's box holds background;
- distractors: some cylinders of the world painted like the target (`distractors=N`; by default 0
  to 2, from the world's name);
- exposure: the light level drifts slowly (two sines, 19 s and 47 s, from 1 at t = 0), and the
  camera's auto-exposure meters every frame and follows with a lag (AE_TAU_S): turning from a bright
  wall to a dark one gives dark frames that brighten.

Motion blur, noise and JPEG are the plain look's. All of it is deterministic: the drift's phases
come from the camera's seeded generator, the rest from the scene and the frame's time.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from emulator.sensors.camera import LOWEST_BIT, TILE, TILES, CameraOptions, Layers, Renderer
from emulator.sensors.textures import BOX, CYLINDER, FLOOR, MATERIALS, TARGET, WALL, level_for, load_textures, sample
from emulator.world.generate import clearance_field
from emulator.world.scene import PATTERNS, Scene
from emulator.world.scene import TARGET as TARGET_LOOK
from protocol.errors import import_optional
from protocol.sensors import CameraSpec, Mount

AMBIENT, DIFFUSE = 0.45, 0.75
WALL_TINT = (70.0, 95.0, 150.0)
"""Brick, B G R."""
FLOOR_TINT = (112.0, 122.0, 128.0)
SKY_TOP, SKY_HORIZON = (215.0, 205.0, 195.0), (180.0, 172.0, 165.0)
SHADOW_M, SHADOW_DEPTH = 0.15, 0.45
"""Contact shadows: how far from a surface they reach, and how dark they are at its foot."""
SHADOW_STEP = 4
"""The shadows are computed every SHADOW_STEP pixels and interpolated (they are soft)."""
AE_TARGET, AE_STRENGTH, AE_TAU_S, AE_RANGE = 110.0, 0.7, 0.5, (0.4, 3.0)
"""Auto-exposure: the mean grey it aims for, how much of the error it corrects, its time constant
and the range of its gain."""
DRIFT = ((0.15, 19.0), (0.10, 47.0))
"""Light level: (amplitude, period in s) of each sine."""
EDGE = 0.1
"""Width of the cut-out's soft edge, in radii of the target's cylinder."""
_KIND_MATERIAL = {"wall": WALL, "box": BOX, "cylinder": CYLINDER, "target": TARGET}
_INV_TEXEL = np.array([1.0 / m.texel_m for m in MATERIALS], dtype=np.float32)
_TEXEL_M = np.array([m.texel_m for m in MATERIALS], dtype=np.float32)


def _profile(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """Half-width of the target's figure, in radii, at height fraction v (0: floor, 1: top): a body,
    shoulders narrowing to a neck, and a round head."""
    body = np.where(v < 0.62, 0.92, 0.92 - 0.52 * np.clip((v - 0.62) / 0.12, 0, 1) ** 0.7)
    head = 0.5 * np.sqrt(np.clip(1 - ((v - 0.875) / 0.125) ** 2, 0, 1))
    return np.asarray(np.where(v < 0.75, body, np.maximum(head, np.where(v < 0.77, 0.4, 0.0))), dtype=np.float64)


PROFILE = _profile(np.linspace(0.0, 1.0, 256)).astype(np.float32)


def cut_out(v: NDArray[np.float32], offset: NDArray[np.float32]) -> NDArray[np.float32]:
    """Alpha of the target's figure at height fraction `v` and signed offset from its axis (radii)."""
    half = PROFILE[np.clip(v * 255, 0, 255).astype(np.int32)]
    return np.asarray(np.clip((half - np.abs(offset)) / EDGE + 0.5, 0, 1), dtype=np.float32)


def light_direction(world: str) -> tuple[float, float]:
    """The light of the world named `world`: a horizontal unit vector towards it, from the name."""
    azimuth = 2 * math.pi * (zlib.crc32(f"{world}:light".encode()) % 3600) / 3600
    return math.cos(azimuth), math.sin(azimuth)


def distractors(scene: Scene, count: int | None) -> frozenset[int]:
    """Shapes (cylinders) painted like the target: the first `count`, or 0..2 by the world's name."""
    n = zlib.crc32(scene.name.encode()) % 3 if count is None else count
    return frozenset([i for i, s in enumerate(scene.shapes) if s.kind == "cylinder"][:n])


@dataclass(frozen=True, slots=True)
class _Tables:
    """Per (column, layer) of a frame, flat: what painting a pixel of that surface needs."""

    zc: NDArray[np.float32]
    """Perpendicular depth / fy: metres per pixel row."""
    u: NDArray[np.float32]
    material: NDArray[np.int64]
    level: NDArray[np.int32]
    pattern: NDArray[np.int64]
    both: NDArray[np.float32]
    """(W * k * 2, 3): both colours, lit."""
    offset: NDArray[np.float32]
    """Signed offset of the ray from a circle's axis, in radii (0 for segments)."""
    is_target: NDArray[np.bool_]
    height: NDArray[np.float32]


class PhotoRenderer(Renderer):
    def __init__(self, spec: CameraSpec, mount: Mount, options: CameraOptions) -> None:
        super().__init__(spec, mount, options)
        self.textures = load_textures().reshape(-1)
        h, w = options.height, options.width
        z = self.floor_z.astype(np.float32)[:, None]
        # Texels a floor pixel covers: across (z / fx) and along the floor (z^2 / (fy h_cam)).
        footprint = np.sqrt((z / self.fx) * (z * z / (self.fy * mount.z_m))) / _TEXEL_M[FLOOR]
        self.floor_level = level_for(footprint)
        self.floor_fade = (1.0 / (1.0 + 0.04 * z))[..., None].astype(np.float32)
        sky = np.linspace(0.0, 1.0, h, dtype=np.float32)[:, None, None]
        self.background = np.broadcast_to(
            np.array(SKY_TOP, np.float32) * (1 - sky) + np.array(SKY_HORIZON, np.float32) * sky, (h, w, 3)
        ).copy()
        self.sky_floor = np.array(SKY_HORIZON, dtype=np.float32)
        self.pix_rows = np.repeat(np.arange(h, dtype=np.int64), w)
        self.pix_cols = np.tile(np.arange(w, dtype=np.int64), h)
        self._opaque_map: NDArray[np.bool_] | None = None
        self._gain: float | None = None
        self._gain_t = 0.0
        self._phases: tuple[float, float] | None = None
        self._origin = np.zeros(2)

    # -- the floor ---------------------------------------------------------------------------------
    def _floor(self, img: NDArray[np.float32], scene: Scene, cam_x: float, cam_y: float, heading: float) -> None:
        z = self.floor_z32
        lateral = self.floor_lateral * z
        c, s = np.float32(math.cos(heading)), np.float32(math.sin(heading))
        wx = np.float32(cam_x) + c * z - s * lateral
        wy = np.float32(cam_y) + s * z + c * lateral
        inv = _INV_TEXEL[FLOOR]
        lum = sample(self.textures, np.int64(FLOOR), self.floor_level, wx * inv, wy * inv)
        lit = lum * self._shadows(scene, wx, wy)
        colour = np.array(FLOOR_TINT, dtype=np.float32) * lit[..., None]
        img[self.floor_rows] = colour * self.floor_fade + self.sky_floor * (1 - self.floor_fade)

    def _shadows(self, scene: Scene, wx: NDArray[np.float32], wy: NDArray[np.float32]) -> NDArray[np.float32]:
        """Darkening of each floor pixel by its distance to the nearest surface (the target's too)."""
        cv2 = import_optional("cv2", "vision", "the emulated camera")
        step = SHADOW_STEP
        coarse_x, coarse_y = wx[::step, ::step], wy[::step, ::step]
        points = np.column_stack([coarse_x.ravel(), coarse_y.ravel()]).astype(np.float64)
        gap = clearance_field(scene, points, skip_target=False).reshape(coarse_x.shape)
        dark = SHADOW_DEPTH * (1 - np.clip(gap / SHADOW_M, 0, 1)) ** 2
        shade = (1 - dark).astype(np.float32)
        return np.asarray(cv2.resize(shade, (wx.shape[1], wx.shape[0]), interpolation=cv2.INTER_LINEAR))

    # -- the surfaces ------------------------------------------------------------------------------
    def _paint(self, img: NDArray[np.float32], scene: Scene, lay: Layers) -> NDArray[np.float32]:
        tab = self._tables(scene, lay)
        layer = lay.layer.reshape(-1)
        out = np.copy(img.reshape(-1, 3))
        shown = np.flatnonzero(layer >= 0)  # only pixels on a surface: often half the frame is floor and sky
        out[shown] = self._colours(tab, lay, self.pix_rows[shown], self.pix_cols[shown], layer[shown])
        cell = lay.cells(lay.layer)
        figure = np.flatnonzero((layer >= 0) & tab.is_target[cell])
        self._opaque_map = None
        if figure.size:
            # The figure's alpha: where it is not opaque, the surface behind it (the next bit of the
            # pixel's coverage mask) or the floor and background already in `img` shows through.
            c, rows = cell[figure], self.pix_rows[figure]
            v = (np.float32(self.mount.z_m) + (np.float32(self.cy) - rows) * tab.zc[c]) / tab.height[c]
            alpha = cut_out(v.astype(np.float32), tab.offset[c])[:, None]
            mask = lay.mask.reshape(-1)[figure]
            behind_layer = LOWEST_BIT[mask & (mask - 1)]
            behind = self._colours(tab, lay, rows, self.pix_cols[figure], behind_layer)
            behind = np.where((behind_layer >= 0)[:, None], behind, img.reshape(-1, 3)[figure])
            out[figure] = alpha * out[figure] + (1 - alpha) * behind
            opaque = np.ones(layer.shape, dtype=bool)
            opaque[figure] = alpha[:, 0] > 0.5
            self._opaque_map = opaque.reshape(lay.layer.shape)
        return out.reshape(img.shape)

    def _opaque(self, lay: Layers) -> NDArray[np.bool_] | bool:
        return True if self._opaque_map is None else self._opaque_map

    def _colours(
        self, tab: _Tables, lay: Layers, rows: NDArray[np.int64], cols: NDArray[np.int64], layer: NDArray[np.int32]
    ) -> NDArray[np.float32]:
        """(N, 3) colours of the pixels (rows, cols) on their surfaces `layer` (-1: any)."""
        cell = cols * lay.k + np.maximum(layer, 0)
        height = np.float32(self.mount.z_m) + (np.float32(self.cy) - rows).astype(np.float32) * tab.zc[cell]
        u = tab.u[cell]
        material = tab.material[cell]
        inv = _INV_TEXEL[material]
        lum = sample(self.textures, material, tab.level[cell], height * inv, u * inv)
        iv = (height * 100).astype(np.int32) % TILE
        iu = (u * 100).astype(np.int32) % TILE
        alt = TILES[tab.pattern[cell], iv, iu]
        return np.asarray(tab.both[cell * 2 + alt] * lum[:, None], dtype=np.float32)

    def _tables(self, scene: Scene, lay: Layers) -> _Tables:
        shapes = scene.shapes
        fake = distractors(scene, self.options.distractors)
        material = np.array([TARGET if i in fake else _KIND_MATERIAL.get(s.kind, BOX) for i, s in enumerate(shapes)])
        look = next((s for s in shapes if s.kind == "target"), TARGET_LOOK)
        stripes = PATTERNS.index("stripes")
        pattern = np.where(material == TARGET, stripes, 0)
        first = [
            look.colour if m == TARGET else WALL_TINT if m == WALL else s.colour
            for s, m in zip(shapes, material, strict=True)
        ]
        second = [look.colour2 if m == TARGET else (0, 0, 0) for m in material]
        shape = lay.shape
        lit = self._lambert(scene, lay)[..., None, None]
        both = np.stack([np.array(first, np.float32)[shape], np.array(second, np.float32)[shape]], axis=2) * lit
        zc = (lay.z / self.fy).astype(np.float32)
        mat = material[shape]
        is_circle = lay.order >= scene.segments.shape[0]
        return _Tables(
            zc=zc.reshape(-1),
            u=lay.u.astype(np.float32).reshape(-1),
            material=mat.reshape(-1).astype(np.int64),
            level=level_for(zc / _TEXEL_M[mat]).reshape(-1),
            pattern=pattern[shape].reshape(-1).astype(np.int64),
            both=both.astype(np.float32).reshape(-1, 3),
            offset=self._offsets(scene, lay).reshape(-1),
            is_target=(is_circle & (np.array([s.kind == "target" for s in shapes])[shape])).reshape(-1),
            height=scene.heights[shape].astype(np.float32).reshape(-1),
        )

    def _normals(self, scene: Scene, lay: Layers) -> NDArray[np.float64]:
        """(W, k, 2) unit normals of the surfaces hit, facing the camera."""
        n_seg = scene.segments.shape[0]
        origin = self._origin
        t = np.where(np.isfinite(lay.t), lay.t, 0.0)
        hit = origin + t[..., None] * lay.dirs[:, None, :]
        normal = np.zeros(hit.shape)
        if n_seg:
            seg = scene.segments
            e = seg[:, 2:4] - seg[:, 0:2]
            perp = np.column_stack([-e[:, 1], e[:, 0]]) / np.maximum(np.hypot(e[:, 0], e[:, 1]), 1e-12)[:, None]
            normal = perp[np.clip(lay.order, 0, n_seg - 1)]
        if scene.circles.shape[0]:
            cir = scene.circles[np.clip(lay.order - n_seg, 0, scene.circles.shape[0] - 1)]
            radial = (hit - cir[..., :2]) / np.maximum(cir[..., 2:3], 1e-12)
            normal = np.where((lay.order >= n_seg)[..., None], radial, normal)
        facing = np.sum(normal * lay.dirs[:, None, :], axis=2) > 0
        return np.where(facing[..., None], -normal, normal)

    def _lambert(self, scene: Scene, lay: Layers) -> NDArray[np.float32]:
        lx, ly = light_direction(scene.name)
        n = self._normals(scene, lay)
        return (AMBIENT + DIFFUSE * np.maximum(0.0, n[..., 0] * lx + n[..., 1] * ly)).astype(np.float32)

    def _offsets(self, scene: Scene, lay: Layers) -> NDArray[np.float32]:
        n_seg, n_cir = scene.segments.shape[0], scene.circles.shape[0]
        if n_cir == 0:
            return np.zeros(lay.order.shape, dtype=np.float32)
        cir = scene.circles[np.clip(lay.order - n_seg, 0, n_cir - 1)]
        fx, fy = cir[..., 0] - self._origin[0], cir[..., 1] - self._origin[1]
        d = lay.dirs[:, None, :]
        offset = (d[..., 0] * fy - d[..., 1] * fx) / np.maximum(cir[..., 2], 1e-12)
        return np.where(lay.order >= n_seg, offset, 0.0).astype(np.float32)

    def _surfaces(self, img: NDArray[np.float32], scene: Scene, cam_x: float, cam_y: float, heading: float) -> None:
        self._origin = np.array([cam_x, cam_y])
        super()._surfaces(img, scene, cam_x, cam_y, heading)

    # -- exposure ----------------------------------------------------------------------------------
    def _expose(self, img: NDArray[np.float32], time_s: float, rng: np.random.Generator) -> NDArray[np.float32]:
        if self._phases is None:
            self._phases = (float(rng.uniform(0, 2 * math.pi)), float(rng.uniform(0, 2 * math.pi)))
        light = 1.0 + sum(
            a * (math.sin(2 * math.pi * time_s / period + phase) - math.sin(phase))
            for (a, period), phase in zip(DRIFT, self._phases, strict=True)
        )
        img *= np.float32(light)
        metered = float(img[::8, ::8].mean())
        want = min(max((AE_TARGET / max(metered, 1.0)) ** AE_STRENGTH, AE_RANGE[0]), AE_RANGE[1])
        if self._gain is None or time_s <= self._gain_t:
            self._gain = want  # the first frame: settled
        else:
            self._gain += (want - self._gain) * (1 - math.exp(-(time_s - self._gain_t) / AE_TAU_S))
        self._gain_t = time_s
        img *= np.float32(self._gain * self.options.exposure)
        return img


def renderer_for(spec: CameraSpec, mount: Mount, options: CameraOptions) -> Renderer:
    """The renderer of `options.look`."""
    return PhotoRenderer(spec, mount, options) if options.look == "photo" else Renderer(spec, mount, options)
