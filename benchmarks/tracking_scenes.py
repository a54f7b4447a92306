"""The scenes benchmarks/tracking.py runs its trackers on, each a list of 320x240 frames at 30 fps
with the truth: the object's box (None while it is out of the picture) and the share of it in view.

* `slide`, `easy`, `medium`, `hard`, `small-plain`, `small-textured`: tests/support/photo_sequences.py's
  sequences built from the photographs the tracker was tuned on, and `held-*` the same kinds built
  from OpenCV's sample photographs, which it was not (visible: the share of the target inside the
  frame and not behind the pole);
* `follow`: the emulator's Pi Camera v2 model in world random:3 from a robot trailing the moving
  target 1.2 m behind with a lagging, swaying heading, so the target wanders across the image and
  changes size (visible: the share of its box inside the frame; the room's obstacles passing in
  front are not counted, the scene's truth does not say);
* `lost`: the follow clip's first frame (where every tracker starts), then frames looking away
  from the target: what a frame costs while re-detecting, and whether clutter passes for it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from emulator.sensors.camera import CameraOptions, Renderer
from emulator.sensors.target import camera_mount, render_target
from emulator.world import load_world
from host_sdk.body import CameraModel
from protocol.sensors import DEVICES
from tests.support import photo_sequences

Box = tuple[float, float, float, float]
"""x, y (top-left), width, height in pixels."""
SIZE = (320, 240)
FPS = 30.0
PHOTO_SCENES = tuple(s.name for s in photo_sequences.SPECS)
PHOTO_SET = {s.name: s.photos for s in photo_sequences.SPECS}
"""Each photo scene's set: tune (the photographs the tracker was tuned on) or held-out."""
SETS = photo_sequences.SETS
EMULATOR_SCENES = ("follow", "lost")
NAMES = (*PHOTO_SCENES, *EMULATOR_SCENES)
OUT_OF_VIEW = 0.3
"""An emulator box with less than this share inside the frame is out of the picture (as in the photo
sequences)."""


@dataclass(frozen=True)
class Shot:
    image: np.ndarray
    time_s: float
    box: Box | None
    """The truth, None while the object is out of the picture."""
    visible: float
    """Share (0..1) of the object in view."""


@dataclass(frozen=True)
class Scene:
    name: str
    source: str
    """"photos" or "emulator"."""
    shots: tuple[Shot, ...]
    camera: CameraModel
    template: np.ndarray | None = None
    """An image of the object (the emulator's): RoverLink's tracker starts from it. Without one,
    every tracker starts from the first shot's true box, as a user's selection."""
    height_m: float | None = None
    fps: float = FPS


def photo_scene(seq: photo_sequences.Sequence) -> Scene:
    shots = tuple(Shot(f.image, f.time_s, f.box, f.visible) for f in seq.frames)
    return Scene(seq.name, "photos", shots, CameraModel.pi_camera_v2(*SIZE), fps=photo_sequences.FPS)


def _in_frame(box: Box) -> tuple[Box | None, float]:
    """The box clipped to the frame, and the share of it inside."""
    x, y, w, h = box
    x0, y0, x1, y1 = max(0.0, x), max(0.0, y), min(float(SIZE[0]), x + w), min(float(SIZE[1]), y + h)
    if x1 <= x0 or y1 <= y0 or w <= 0 or h <= 0:
        return None, 0.0
    share = (x1 - x0) * (y1 - y0) / (w * h)
    return ((x0, y0, x1 - x0, y1 - y0), share) if share >= OUT_OF_VIEW else (None, share)


def emulator_shots(n: int, *, look_away: bool = False) -> tuple[list[Shot], np.ndarray, float, CameraModel]:
    """`n` frames of the follow drive (or looking the other way), the target's image and height."""
    world = load_world("random:3")
    mount = camera_mount("picar")
    template = render_target(world, mount)
    renderer = Renderer(DEVICES["pi-camera-v2"], mount, CameraOptions())  # type: ignore[arg-type]
    camera = CameraModel.pi_camera_v2(*SIZE, mount_x_m=mount.x_m)
    assert world.target is not None
    radius = world.target.radius_m
    rng = np.random.default_rng(3)
    out: list[Shot] = []
    heading = None
    for i in range(n):
        t = i / FPS
        world.set_time(t)
        tx, ty, th, _ = world.target_pose()  # type: ignore[misc]
        aim = math.atan2(math.sin(th), math.cos(th))
        heading = aim if heading is None else heading + 0.15 * math.remainder(aim - heading, 2 * math.pi)
        look = heading + 0.25 * math.sin(0.7 * t) + (math.pi if look_away else 0.0)
        back = 1.2 + 0.5 * math.sin(0.3 * t)
        x, y = tx - back * math.cos(heading), ty - back * math.sin(heading)
        image = renderer.render(world, (x, y, look), 0.0, rng)
        cx, cy = x + mount.x_m * math.cos(look), y + mount.x_m * math.sin(look)
        bearing = math.remainder(math.atan2(ty - cy, tx - cx) - look, 2 * math.pi)
        depth = math.hypot(tx - cx, ty - cy) * math.cos(bearing) - radius
        box, visible = None, 0.0
        if depth > 0.05:  # in front of the camera
            half = camera.fx * radius / depth
            top = camera.cy - camera.fy * (0.3 - mount.z_m) / depth
            box, visible = _in_frame((camera.column(bearing) - half, top, 2 * half, camera.fy * 0.3 / depth))
        out.append(Shot(image, t, box, visible))
    return out, template.image, template.height_m, camera


def emulator_scene(name: str, seconds: float) -> Scene:
    n = max(2, round(seconds * FPS))
    if name == "follow":
        shots, template, height, camera = emulator_shots(n)
    else:  # every tracker starts where the follow clip does, then the robot looks away
        start, template, height, camera = emulator_shots(1)
        away, _, _, _ = emulator_shots(n + 1, look_away=True)
        shots = start + away[1:]  # n frames without the target
    return Scene(name, "emulator", tuple(shots), camera, template, height)


def scenes(names: Sequence[str] | None, *, follow_s: float, lost_s: float) -> list[Scene]:
    """The scenes named (all by default), in NAMES' order."""
    wanted = [n for n in NAMES if names is None or n in names]
    photos = tuple(n for n in wanted if n in PHOTO_SCENES)
    out = [photo_scene(s) for s in photo_sequences.sequences(photos)] if photos else []
    out += [emulator_scene(n, follow_s if n == "follow" else lost_s) for n in wanted if n in EMULATOR_SCENES]
    return out
