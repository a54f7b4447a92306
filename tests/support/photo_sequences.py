"""Tracking sequences built from real photographs, seeded and reproducible, in two disjoint sets.

`tune` is built from scikit-image's photographs in tests/data/photos (the tracker's parameters were
chosen on these); `held-out` from other photographs, OpenCV's sample data as Debian's `opencv-doc`
installs it (scripts/test.sh installs the package), which no parameter was chosen on. Each set has
sequences with a small, far target (about 34 px across): a plain one and a textured one.

A target cut out of a photo with a soft elliptical edge (so its bounding box holds background, as a
user's selection does) moves over another real, cluttered photo while the camera pans; it nears and
recedes, turns a few degrees, the exposure changes, a pole passes in front of it, it leaves the
picture and comes back. Every frame goes through JPEG at quality 60, as an MJPEG camera sends it.

    for seq in sequences():
        for frame in seq.frames:
            frame.image, frame.time_s, frame.box   # box: the truth (x, y, w, h), None while out of view
            frame.visible                            # share of the target seen: in the frame, not behind the pole

The truth box is the bounding box of the target's visible alpha (> 0.5) clipped to the frame; it is
None while less than 30 % of the target is inside the frame. A pole in front does not make it None
(the object's box includes its occluded part, as in the usual tracking benchmarks); it lowers
`visible`, the share of the target's alpha that is inside the frame and not behind the pole.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import cv2
import numpy as np

PHOTOS = Path(__file__).resolve().parents[1] / "data" / "photos"
OPENCV_SAMPLES = Path("/usr/share/doc/opencv-doc/examples/data")
"""OpenCV's sample photographs, from Debian's opencv-doc (apt-get install opencv-doc)."""
FOLDERS = {"tune": PHOTOS, "held-out": OPENCV_SAMPLES}
SETS = tuple(FOLDERS)
SIZE = (320, 240)
FPS = 30.0
Box = tuple[float, float, float, float]


@dataclass(frozen=True)
class Cutout:
    photo: str
    centre: tuple[int, int]
    radii: tuple[int, int]
    """Ellipse of the object in the photo, pixels."""
    photos: str = "tune"
    """The set its photo belongs to (FOLDERS)."""


CUTOUTS = {
    "cat": Cutout("chelsea.jpg", (150, 100), (105, 88)),  # a textured face
    "cup": Cutout("coffee.jpg", (218, 178), (160, 126)),  # a red cup on its saucer: few corners
    "baboon": Cutout("baboon.jpg", (256, 250), (200, 210), "held-out"),  # a face, strongly coloured
    "squirrel": Cutout("squirrel_cls.jpg", (262, 222), (112, 158), "held-out"),  # fur, soft, brown
    "orange": Cutout("orange.jpg", (250, 272), (196, 196), "held-out"),  # one colour, almost no texture
    "apple": Cutout("apple.jpg", (252, 268), (196, 212), "held-out"),  # red, a highlight, no corners
}


@dataclass(frozen=True)
class Spec:
    name: str
    target: str
    background: str
    seed: int
    photos: str = "tune"
    """The set (FOLDERS) the target's and the background's photographs come from."""
    frames: int = 150
    height_px: float = 70.0
    """The target's height in the frame at scale 1."""
    sway_px: float = 70.0
    """How far the target wanders from the centre, horizontally (60 % of that vertically)."""
    pan_px: float = 60.0
    """Camera pan: how far the background slides."""
    scale: tuple[float, float] = (1.0, 1.0)
    rotation_deg: float = 0.0
    exposure: float = 0.0
    """Gain swing (0.2: 0.8x to 1.2x), plus a step of that size mid-sequence (auto-exposure)."""
    occlusion: tuple[int, int, float] | None = None
    """First frame, frames, width of the pole as a fraction of the target's width."""
    out: tuple[int, int] | None = None
    """First frame the target is gone, frames it stays gone (it leaves and returns over 8 frames)."""
    jpeg: int = 60


SPECS = (
    Spec("slide", "cat", "astronaut.jpg", seed=1, frames=90, sway_px=80.0, pan_px=0.0),
    Spec("easy", "cat", "rocket.jpg", seed=2, scale=(0.85, 1.2), rotation_deg=3.0, exposure=0.15,
         occlusion=(40, 20, 0.3), out=(95, 20)),
    Spec("medium", "cat", "coffee.jpg", seed=3, scale=(0.7, 1.3), rotation_deg=4.0, exposure=0.2,
         occlusion=(35, 24, 0.4), out=(90, 28)),
    Spec("hard", "cup", "astronaut.jpg", seed=4, sway_px=90.0, pan_px=90.0, scale=(0.6, 1.4), rotation_deg=6.0,
         exposure=0.3, occlusion=(30, 24, 0.45), out=(85, 32)),
    Spec("small-plain", "cup", "rocket_launch.jpg", seed=5, height_px=34.0, sway_px=90.0, pan_px=60.0,
         scale=(0.9, 1.15), rotation_deg=3.0, exposure=0.2, occlusion=(40, 16, 0.3), out=(95, 24)),
    Spec("small-textured", "cat", "astronaut_collins.jpg", seed=6, height_px=34.0, sway_px=90.0, pan_px=60.0,
         scale=(0.9, 1.15), rotation_deg=3.0, exposure=0.2, occlusion=(40, 16, 0.3), out=(95, 24)),
    Spec("held-slide", "baboon", "building.jpg", seed=11, photos="held-out", frames=90, sway_px=80.0, pan_px=0.0),
    Spec("held-easy", "squirrel", "leuvenA.jpg", seed=12, photos="held-out", scale=(0.85, 1.2), rotation_deg=3.0,
         exposure=0.15, occlusion=(40, 20, 0.3), out=(95, 20)),
    Spec("held-medium", "baboon", "home.jpg", seed=13, photos="held-out", scale=(0.7, 1.3), rotation_deg=4.0,
         exposure=0.2, occlusion=(35, 24, 0.4), out=(90, 28)),
    Spec("held-hard", "apple", "stuff.jpg", seed=14, photos="held-out", sway_px=90.0, pan_px=90.0,
         scale=(0.6, 1.4), rotation_deg=6.0, exposure=0.3, occlusion=(30, 24, 0.45), out=(85, 32)),
    Spec("held-small-plain", "orange", "building.jpg", seed=15, photos="held-out", height_px=34.0, sway_px=90.0,
         pan_px=60.0, scale=(0.9, 1.15), rotation_deg=3.0, exposure=0.2, occlusion=(40, 16, 0.3), out=(95, 24)),
    Spec("held-small-textured", "squirrel", "leuvenB.jpg", seed=16, photos="held-out", height_px=34.0,
         sway_px=90.0, pan_px=60.0, scale=(0.9, 1.15), rotation_deg=3.0, exposure=0.2, occlusion=(40, 16, 0.3),
         out=(95, 24)),
)  # fmt: skip


@dataclass(frozen=True)
class Frame:
    image: np.ndarray
    time_s: float
    box: Box | None
    visible: float = 1.0
    """Share (0..1) of the target's alpha inside the frame and not behind the pole."""


@dataclass(frozen=True)
class Sequence:
    spec: Spec
    frames: tuple[Frame, ...]

    @property
    def name(self) -> str:
        return self.spec.name


@cache
def photo(name: str, photos: str = "tune") -> np.ndarray:
    path = FOLDERS[photos] / name
    image = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if image is None:
        where = " (Debian's opencv-doc: apt-get install opencv-doc)" if photos == "held-out" else ""
        raise FileNotFoundError(f"{path}: no such photograph{where}")
    return np.asarray(image, dtype=np.uint8)


@cache
def cutout(name: str) -> tuple[np.ndarray, np.ndarray]:
    """The object's pixels (BGR float) and its soft alpha (0..1), cropped to the ellipse's box."""
    c = CUTOUTS[name]
    img = photo(c.photo, c.photos)
    (cx, cy), (rx, ry) = c.centre, c.radii
    x0, y0, x1, y1 = max(0, cx - rx), max(0, cy - ry), min(img.shape[1], cx + rx), min(img.shape[0], cy + ry)
    alpha = np.zeros(img.shape[:2], np.float32)
    cv2.ellipse(alpha, (cx, cy), (rx - 4, ry - 4), 0, 0, 360, 1.0, -1)
    alpha = cv2.GaussianBlur(alpha, (0, 0), 3.0)  # a soft edge: a real object's outline is not a step
    return img[y0:y1, x0:x1].astype(np.float32), alpha[y0:y1, x0:x1]


def _wave(rng: np.random.Generator, t: np.ndarray, periods: tuple[float, ...]) -> np.ndarray:
    """A smooth random path in -1..1: a few sines with random phases."""
    out = sum(np.sin(2 * math.pi * t / p + rng.uniform(0, 2 * math.pi)) for p in periods)
    return np.asarray(out, dtype=np.float64) / len(periods)


def _smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def _paths(spec: Spec, rng: np.random.Generator) -> dict[str, np.ndarray]:
    t = np.arange(spec.frames) / FPS
    W, H = SIZE
    side = 1.0 if rng.random() < 0.5 else -1.0
    away = np.zeros_like(t)
    if spec.out is not None:
        start, length = spec.out
        i = np.arange(spec.frames)
        away = _smoothstep((i - (start - 8)) / 8) * (1 - _smoothstep((i - (start + length)) / 8))
    lo, hi = spec.scale
    return {
        "x": W / 2 + spec.sway_px * _wave(rng, t, (3.1, 1.7)) + side * away * (W / 2 + 2.2 * spec.height_px),
        "y": H / 2 + 0.6 * spec.sway_px * _wave(rng, t, (2.3, 1.3)),
        "scale": lo + (hi - lo) * (0.5 + 0.5 * _wave(rng, t, (4.3, 2.9))),
        "angle": spec.rotation_deg * _wave(rng, t, (2.7, 1.9)),
        "pan_x": spec.pan_px * _wave(rng, t, (3.7, 2.1)),
        "pan_y": 0.4 * spec.pan_px * _wave(rng, t, (2.9,)),
        "gain": 1.0 + spec.exposure * (_wave(rng, t, (2.5,)) + np.where(t > t[-1] / 2, 0.8, 0.0)) / 1.8,
    }


def _render(spec: Spec, p: dict[str, np.ndarray], i: int, rng: np.random.Generator) -> Frame:
    W, H = SIZE
    bg = photo(spec.background, spec.photos)
    bx = (bg.shape[1] - W) / 2 + p["pan_x"][i]
    by = (bg.shape[0] - H) / 2 + p["pan_y"][i]
    shift = np.array([[1.0, 0.0, -bx], [0.0, 1.0, -by]])
    frame = cv2.warpAffine(bg, shift, SIZE, flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT).astype(np.float32)
    pix, alpha = cutout(spec.target)
    s = spec.height_px / alpha.shape[0] * p["scale"][i]
    m = cv2.getRotationMatrix2D((alpha.shape[1] / 2, alpha.shape[0] / 2), float(p["angle"][i]), s)
    m[:, 2] += (p["x"][i] - alpha.shape[1] / 2, p["y"][i] - alpha.shape[0] / 2)
    obj = cv2.warpAffine(pix, m, SIZE, flags=cv2.INTER_LINEAR)
    a = cv2.warpAffine(alpha, m, SIZE, flags=cv2.INTER_LINEAR)
    full_area = float(alpha.sum()) * s * s
    a3 = a[..., None]
    frame = frame * (1 - a3) + obj * a3
    pole = _pole_span(spec, p, i)
    hidden = 0.0
    if pole is not None:
        x0, x1 = pole
        strip = bg[: SIZE[1], x1 - x0 : 2 * (x1 - x0)].astype(np.float32)  # a piece of the scene
        frame[: strip.shape[0], x0:x1] = strip[:, : x1 - x0]
        hidden = float(a[: strip.shape[0], x0:x1].sum())
    frame = frame * np.float32(p["gain"][i]) + 2.0 * rng.standard_normal(frame.shape, dtype=np.float32)
    image = np.clip(frame, 0, 255).astype(np.uint8)
    ok, jpeg = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, spec.jpeg])
    assert ok
    sent = np.asarray(cv2.imdecode(jpeg, cv2.IMREAD_COLOR), dtype=np.uint8)
    box = None
    if float(a.sum()) >= 0.3 * full_area:
        ys, xs = np.nonzero(a > 0.5)
        x0, y0, x1, y1 = xs.min(), ys.min(), xs.max() + 1, ys.max() + 1
        box = (float(x0), float(y0), float(x1 - x0), float(y1 - y0))
    visible = float(min(1.0, (float(a.sum()) - hidden) / full_area))
    return Frame(sent, i / FPS, box, visible)


def _pole_span(spec: Spec, p: dict[str, np.ndarray], i: int) -> tuple[int, int] | None:
    """The columns of frame `i` that a vertical bar (another part of the background photo) covers
    as it crosses the target left to right; None when there is no bar."""
    if spec.occlusion is None:
        return None
    start, length, frac = spec.occlusion
    if not start <= i < start + length:
        return None
    w_obj = spec.height_px * p["scale"][i] * 1.2
    width = max(4, round(frac * w_obj))
    progress = (i - start + 0.5) / length
    x0 = round(p["x"][i] - w_obj / 2 - width / 2 + progress * w_obj)
    x0c, x1c = max(0, x0), min(SIZE[0], x0 + width)
    return (x0c, x1c) if x1c > x0c else None


def build(spec: Spec) -> Sequence:
    assert CUTOUTS[spec.target].photos == spec.photos, f"{spec.name}: its target and background are of one set"
    rng = np.random.default_rng(spec.seed)
    paths = _paths(spec, rng)
    return Sequence(spec, tuple(_render(spec, paths, i, rng) for i in range(spec.frames)))


def sequences(names: tuple[str, ...] | None = None, photos: str | None = None) -> list[Sequence]:
    """The sequences named (all: None), of one set (`photos`; both: None)."""
    return [build(s) for s in SPECS if (names is None or s.name in names) and photos in (None, s.photos)]


def iou(a: Box | None, b: Box | None) -> float:
    if a is None or b is None:
        return 0.0
    ax, ay, aw, ah = a
    bx, by, bw, bh = b
    iw = max(0.0, min(ax + aw, bx + bw) - max(ax, bx))
    ih = max(0.0, min(ay + ah, by + bh) - max(ay, by))
    inter = iw * ih
    union = aw * ah + bw * bh - inter
    return inter / union if union > 0 else 0.0
