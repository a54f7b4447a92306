"""The emulated camera's photo look (emulator/sensors/photo.py) against the plain one: textures,
a target that is not a rectangle, lighting and auto-exposure, look-alikes, the template photo, and
the same frames for the same seed."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest
from numpy.typing import NDArray

from emulator import Emulator
from emulator.errors import EmulatorValueError
from emulator.sensors import attach, camera_options
from emulator.sensors import textures as textures_module
from emulator.sensors.camera import CameraOptions, Renderer
from emulator.sensors.mjpeg import CameraDevice, Frame
from emulator.sensors.photo import distractors, light_direction, renderer_for
from emulator.sensors.target import camera_mount, render_target
from emulator.sensors.textures import TextureMissingError
from emulator.transport.devices import sensor_options, target_part
from emulator.world import load_world
from emulator.world.scene import CYLINDER, TARGET, WALL, Scene, Shape, Target, TargetPath, make_scene
from protocol.sensors import DEVICES, CameraSpec
from protocol.toml import tomllib
from roverlink.cli import build_parser

MOUNT = camera_mount("picar")
SPEC = DEVICES["pi-camera-v2"]
assert isinstance(SPEC, CameraSpec)


def renderer(look: str, **options: float) -> Renderer:
    return renderer_for(SPEC, MOUNT, CameraOptions(look=look, **options))  # type: ignore[arg-type]


def render(r: Renderer, scene: Scene, pose: tuple[float, float, float], time_s: float = 0.0) -> NDArray[np.uint8]:
    return r.render(scene, pose, 0.0, np.random.default_rng(0), time_s=time_s)


def room(name: str = "room") -> Scene:
    """A wall 1.5 m ahead of the origin (facing -x), nothing else."""
    return make_scene(name, [WALL], [(1.5, -3.0, 1.5, 3.0)], [0], [], cir_shape=[], start=(0, 0, 0), target=None)


def local_variance(grey: NDArray[np.float32]) -> NDArray[np.float32]:
    mean = cv2.blur(grey, (5, 5))
    return np.asarray(cv2.blur(grey * grey, (5, 5)) - mean * mean)


def frames_of(look: str, seed: int, seconds: float) -> list[bytes]:
    emu = Emulator("picar", seed=seed)
    rig = attach(emu, "random:3", camera=camera_options("320x240", look=look))
    camera = rig.devices["camera"]
    assert isinstance(camera, CameraDevice)
    got: list[Frame] = []
    camera.listeners.append(got.append)
    emu.advance(seconds)
    return [f.jpeg for f in got]


def test_the_same_seed_gives_the_same_photo_frames_bit_for_bit() -> None:
    first, again, other = frames_of("photo", 3, 1.0), frames_of("photo", 3, 1.0), frames_of("photo", 4, 1.0)
    assert len(first) == 30 and first == again
    assert first != other  # the seed reaches the frames (sensor noise, the light's drift)


def test_walls_and_floor_carry_photographic_texture() -> None:
    scene = room()
    # No noise: only the textures vary locally. Wall rows 60..130, floor rows 160.. (cf. the room).
    wall, floor = (slice(60, 130), slice(None)), (slice(160, 240), slice(None))
    medians = {}
    for look in ("plain", "photo"):
        grey = cv2.cvtColor(render(renderer(look, noise=0.0), scene, (0.0, 0.0, 0.0)), cv2.COLOR_BGR2GRAY)
        var = local_variance(grey.astype(np.float32))
        medians[look] = (float(np.median(var[wall])), float(np.median(var[floor])))
    assert medians["plain"][0] < 5 and medians["plain"][1] < 5  # flat between the pattern's lines
    assert medians["photo"][0] > 40 and medians["photo"][1] > 40, medians


def target_scene(name: str = "one target", decoy: bool = False) -> Scene:
    """The target 1.2 m ahead of the origin (standing still), a wall behind it, maybe a cylinder."""
    shapes = [WALL, Shape("cylinder", "decoy", 0.4, CYLINDER.colour), TARGET]
    circles = [(2.0, -0.6 if decoy else -50.0, 0.1), (1.32, 0.0, 0.12)]
    target = Target(0.12, TARGET, TargetPath(((1.32, 0.0),), 0.0))
    return make_scene(
        name, shapes, [(3.0, -3.0, 3.0, 3.0)], [0], circles, cir_shape=[1, 2], start=(0, 0, 0), target=target
    )


def test_the_photo_target_is_a_cut_out_whose_box_holds_background() -> None:
    with_target = target_scene()
    without = target_scene()
    without.circles[-1, :2] = (-50.0, -50.0)
    found = {}
    for look in ("plain", "photo"):
        r = renderer(look, noise=0.0)
        image = render(r, with_target, (0.0, 0.0, 0.0)).astype(np.float32)
        assert r.target_bbox is not None
        x0, y0, x1, y1 = r.target_bbox
        empty = render(renderer(look, noise=0.0), without, (0.0, 0.0, 0.0)).astype(np.float32)
        outside = np.ones(image.shape[:2], dtype=bool)
        outside[y0:y1, x0:x1] = False
        # Auto-exposure meters the whole frame: compare the two after matching their gains.
        empty *= image[outside].mean() / empty[outside].mean()
        same = np.abs(image[y0:y1, x0:x1] - empty[y0:y1, x0:x1]).max(axis=2) < 8
        found[look] = float(same.mean())
    assert found["plain"] < 0.03, found  # the plain target fills its box (but for its curved foot)
    assert 0.08 < found["photo"] < 0.5, found  # the figure's shoulders and head leave background


def test_the_light_level_drifts_and_auto_exposure_lags_a_turn() -> None:
    scene = room("exposure")
    r = renderer("photo", noise=0.0)
    means = [float(render(r, scene, (0.0, 0.0, 0.0), t).mean()) for t in (0.0, 4.0, 8.0, 12.0)]
    assert max(means) - min(means) > 0.04 * means[0], means
    plain = renderer("plain", noise=0.0)
    assert len({float(render(plain, scene, (0.0, 0.0, 0.0), t).mean()) for t in (0.0, 4.0, 8.0)}) == 1
    # Two walls facing each other across the light: one lit, one in its shadow.
    lx, ly = light_direction("turn")
    px, py = -ly * 3, lx * 3
    segments = [(lx - px, ly - py, lx + px, ly + py), (-lx - px, -ly - py, -lx + px, -ly + py)]
    walls = [Shape("wall", "tall", 2.0, WALL.colour)]
    turn = make_scene("turn", walls, segments, [0, 0], [], cir_shape=[], start=(0, 0, 0), target=None)
    bright, dark = math.atan2(-ly, -lx), math.atan2(ly, lx)
    r = renderer("photo", noise=0.0)
    for i in range(30):
        render(r, turn, (0.0, 0.0, bright), i / 30)
    after = [float(render(r, turn, (0.0, 0.0, dark), 1.0 + i / 30).mean()) for i in range(1, 61)]
    assert after[0] < 0.8 * after[-1], after  # dark at first, then the exposure opens up
    assert after[5] < after[15] < after[45]


def test_the_target_photo_is_the_rendered_target_cut_out() -> None:
    scene = target_scene()
    template = render_target(scene, MOUNT, look="photo")
    plain = render_target(scene, MOUNT)
    assert template.image.shape == (*plain.image.shape[:2], 4)
    bgr, alpha = np.ascontiguousarray(template.image[..., :3]), template.image[..., 3]
    assert not np.array_equal(bgr, plain.image)
    # A cut-out: the figure's body is opaque, the background beside its head is not.
    h, w = alpha.shape
    assert (alpha[h // 2 :, w // 4 : 3 * w // 4] == 255).mean() > 0.95
    assert (alpha[: h // 8, : w // 6] == 0).mean() > 0.9 and (alpha[: h // 8, -(w // 6) :] == 0).mean() > 0.9
    # Seen from 0.8 m in the camera's frames, with noise: the cut-out is found, on the target.
    r = renderer("photo")
    frame = render(r, scene, (1.32 - 0.12 - 0.8 - MOUNT.x_m, 0.0, 0.0))
    match = cv2.matchTemplate(frame, bgr, cv2.TM_CCOEFF_NORMED, mask=cv2.merge([alpha] * 3))
    _, best, _, (mx, my) = cv2.minMaxLoc(np.nan_to_num(match, nan=-1.0))
    assert float(np.median(np.nan_to_num(match, nan=0.0))) < 0.3  # elsewhere it does not match
    assert r.target_bbox is not None
    x0, y0, x1, _ = r.target_bbox
    assert best > 0.9 and x0 <= mx and mx + w <= x1 + 1 and y0 <= my, (best, mx, my)
    # The emulator's `target` endpoint serves that photo for a photo-look camera (JPEG: no alpha).
    emu = Emulator("picar", seed=1)
    rig = attach(emu, scene, camera=camera_options("320x240", look="photo"))
    part = target_part(rig)
    jpeg = part[part.index(b"\r\n\r\n") + 4 : -2]
    served = cv2.imdecode(np.frombuffer(jpeg, np.uint8), cv2.IMREAD_COLOR)
    assert served.shape == bgr.shape
    assert np.abs(served.astype(np.int16) - bgr).mean() < 8  # JPEG's loss
    assert np.abs(served.astype(np.int16) - plain.image).mean() > 20


def magenta(image: NDArray[np.uint8]) -> int:
    b, g, r = (image[..., i].astype(np.int16) for i in range(3))
    return int(np.count_nonzero((b > 120) & (r > 120) & (g < 0.5 * b)))


def test_distractors_look_like_the_target_when_asked() -> None:
    scene = target_scene("decoys", decoy=True)
    facing_decoy = (0.0, 0.0, math.atan2(-0.6, 2.0))
    counts = {}
    for n in (0, 1):
        r = renderer_for(SPEC, MOUNT, CameraOptions(look="photo", noise=0.0, distractors=n))  # type: ignore[arg-type]
        image = render(r, scene, facing_decoy)
        x0, _, x1, _ = r.target_bbox or (0, 0, 0, 0)
        image[:, x0:x1] = 0  # the real target, when in view
        counts[n] = magenta(image)
    assert counts[0] < 20 and counts[1] > 300, counts
    # By default some worlds have them and some do not.
    assert {len(distractors(load_world(f"random:{seed}"), None)) for seed in range(8)} >= {0, 1, 2}


def test_look_and_distractors_from_urls_and_the_command_line() -> None:
    options = sensor_options({"camera": "320x240", "look": "photo", "distractors": "2"})
    assert options is not None and (options.look, options.distractors) == ("photo", 2)
    default = sensor_options({"camera": "1"})
    assert default is not None and (default.look, default.distractors) == ("plain", None)
    with pytest.raises(EmulatorValueError, match=r"camera look = 'glossy'.*plain or photo"):
        sensor_options({"camera": "1", "look": "glossy"})
    with pytest.raises(EmulatorValueError, match=r"camera distractors = 99.*0\.\.8"):
        sensor_options({"camera": "1", "distractors": "99"})
    with pytest.raises(EmulatorValueError, match=r"camera look = 'photo'.*a camera"):
        sensor_options({"lidar": "rplidar-a1", "look": "photo"})
    args = build_parser().parse_args(["emulate", "--camera", "--camera-look", "photo", "--camera-distractors", "1"])
    assert (args.look, args.distractors) == ("photo", 1)
    assert build_parser().parse_args(["follow", "--world", "random:3", "--camera-look", "photo"]).camera_look == "photo"
    assert build_parser().parse_args(["follow", "--world", "random:3"]).camera_look == "plain"


def test_a_missing_texture_file_is_named(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    shutil.copy(textures_module.TEXTURE_DIR / "brick.png", tmp_path / "brick.png")
    monkeypatch.setattr(textures_module, "TEXTURE_DIR", tmp_path)
    with pytest.raises(TextureMissingError, match=r"camera texture 'grass.png' is missing") as err:
        renderer("photo")
    assert err.value.path == tmp_path / "grass.png"
    renderer("plain")  # the plain look needs no file


def test_the_textures_are_package_data_with_their_licences() -> None:
    # A non-editable install copies only what [tool.setuptools.package-data] names.
    root = Path(__file__).resolve().parents[3]
    patterns = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["emulator"]
    shipped = {p.relative_to(root / "emulator") for pattern in patterns for p in (root / "emulator").glob(pattern)}
    readme = (textures_module.TEXTURE_DIR / "README.md").read_text()
    for material in textures_module.MATERIALS:
        if material.source:
            assert Path("sensors/textures") / material.source in shipped
            assert f"| {material.source} |" in readme and "CC0" in readme
    assert Path("sensors/textures/README.md") in shipped
    total = sum((textures_module.TEXTURE_DIR / p.name).stat().st_size for p in shipped if p.suffix == ".png")
    assert total < 400_000
