"""The emulated target's look as a tracker template: rendered by the emulator's own camera model.

On a real robot the user gives the tracker a photo of the target or selects a region of a frame; on
the emulator the target's shape, colours and pattern are in the scene, so it is rendered once,
straight ahead at a known distance with nothing around it, and the box the cylinder fills is
cropped. An `emu://` robot with a camera serves that picture as its `target` endpoint (one JPEG in
the camera's MJPEG format), so a robot program reads it as it would read a photo. The crop stays
inside the silhouette: the template holds only the target's own pixels, so it matches the target
against any background. The photographic look's figure is not a box (a head on a tapered body):
its template is a cut-out, BGRA with the figure's pixels opaque (found against the same view
rendered without it), as a user's photo with its background removed would be; its `target`
endpoint serves it as the MJPEG format allows, on the plain backdrop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from emulator.sensors.camera import CameraOptions
from emulator.sensors.photo import renderer_for
from emulator.sensors.rig import mount_on
from emulator.world.scene import Scene, make_scene
from protocol.sensors import DEVICES, CameraSpec, Mount


@dataclass(frozen=True, slots=True)
class TargetTemplate:
    image: NDArray[np.uint8]
    """BGR, or BGRA (a cut-out: alpha 255 on the target) for a look whose target is not a box."""
    width_m: float
    """The target's width and height (what the tracker's range estimate uses)."""
    height_m: float
    distance_m: float


def camera_mount(profile: str) -> Mount:
    """Where the profile carries its camera (the emulator's default spot when it has none)."""
    return mount_on(profile, "camera", "pi-camera-v2")


def render_target(
    scene: Scene, mount: Mount, *, width: int = 320, height: int = 240, distance_m: float = 0.8, look: str = "plain"
) -> TargetTemplate:
    """The scene's target seen from `distance_m` (to its front) by a camera at `mount`'s height, in
    the camera's `look`."""
    target = scene.target
    if target is None:
        raise ValueError(f"world {scene.name!r} has no target to follow")
    spec = DEVICES["pi-camera-v2"]
    assert isinstance(spec, CameraSpec)
    r = target.radius_m
    d = distance_m + r
    alone = make_scene(scene.name, [target.shape], [], [], [(d, 0.0, r)], cir_shape=[0], start=(0, 0, 0), target=None)
    cam = Mount(mount.device, "camera", 0.0, 0.0, mount.z_m, 0.0)
    options = CameraOptions(width=width, height=height, noise=0.0, exposure_s=0.0, look=look)
    renderer = renderer_for(spec, cam, options)
    image = renderer.render(alone, (0.0, 0.0, 0.0), 0.0, np.random.default_rng(0))
    z = distance_m
    half = renderer.fx * math.tan(math.asin(r / d))
    top = renderer.cy - renderer.fy * (target.shape.height_m - mount.z_m) / z
    bottom = renderer.cy + renderer.fy * mount.z_m / z
    inset_x, inset_y = 0.12 * half, 0.03 * (bottom - top)
    x0, x1 = math.ceil(renderer.cx - half + inset_x), math.floor(renderer.cx + half - inset_x)
    y0, y1 = math.ceil(max(0.0, top + inset_y)), math.floor(min(height - 1.0, bottom - inset_y))
    crop = image[y0 : y1 + 1, x0 : x1 + 1].copy()
    if look != "plain":
        empty = make_scene(scene.name, [], [], [], [], cir_shape=[], start=(0, 0, 0), target=None)
        backdrop = renderer.render(empty, (0.0, 0.0, 0.0), 0.0, np.random.default_rng(0))[y0 : y1 + 1, x0 : x1 + 1]
        figure = np.abs(crop.astype(np.int16) - backdrop.astype(np.int16)).max(axis=2) > 8
        crop = np.dstack([crop, np.where(figure, 255, 0).astype(np.uint8)])
    # The crop's rows are a slice of the target's height: scale the known height to what it spans.
    span_m = (y1 + 1 - y0) * z / renderer.fy
    return TargetTemplate(crop, 2 * r * (x1 + 1 - x0) / (2 * half), span_m, distance_m)
