"""The tracker on frames rendered by the emulator's camera model, against the scene's truth."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from emulator.sensors.camera import CameraOptions, Renderer
from emulator.sensors.target import camera_mount, render_target
from emulator.world import load_world
from emulator.world.scene import Scene
from host_sdk.body import CameraModel
from host_sdk.errors import CommandRangeError
from host_sdk.perception.template import cutout_core, read_template
from host_sdk.perception.tracking import Tracker, TrackState
from protocol.sensors import DEVICES
from tests.support.photo_sequences import iou

MOUNT = camera_mount("picar")
CAMERA = CameraModel.pi_camera_v2(320, 240, mount_x_m=MOUNT.x_m)


def world() -> Scene:
    return load_world("random:3")


def frames(
    scene: Scene, poses: Iterator[tuple[float, float, float]], fps: float = 30.0, start_s: float = 0.0
) -> Iterator[tuple[np.ndarray, float, float, float]]:
    """(image, time, true bearing of the target from the robot, true range to its front) per pose."""
    renderer = Renderer(DEVICES["pi-camera-v2"], MOUNT, CameraOptions())  # type: ignore[arg-type]
    rng = np.random.default_rng(1)
    for i, (x, y, th) in enumerate(poses):
        t = start_s + i / fps
        scene.set_time(t)
        tx, ty, _, _ = scene.target_pose()  # type: ignore[misc]
        cx, cy = x + MOUNT.x_m * math.cos(th), y + MOUNT.x_m * math.sin(th)
        bearing = math.remainder(math.atan2(ty - cy, tx - cx) - th, 2 * math.pi)
        dist = math.hypot(tx - cx, ty - cy) - scene.target.radius_m  # type: ignore[union-attr]
        yield renderer.render(scene, (x, y, th), 0.0, rng), t, bearing, dist


def behind_target(scene: Scene, back_m: float) -> tuple[float, float, float]:
    scene.set_time(0.0)
    tx, ty, heading, _ = scene.target_pose()  # type: ignore[misc]
    return tx - back_m * math.cos(heading), ty - back_m * math.sin(heading), heading


def test_tracks_a_moving_target_with_its_bearing_and_range() -> None:
    scene = world()
    template = render_target(scene, MOUNT)
    tracker = Tracker(template.image, CAMERA, height_m=template.height_m)
    pose = behind_target(scene, 1.2)
    states, bearing_err, range_err = [], [], []
    for image, t, bearing, dist in frames(scene, iter([pose] * 150)):
        track = tracker.update(image, t)
        states.append(track.state)
        if track.found:
            assert track.bearing_rad is not None and track.range_m is not None
            bearing_err.append(abs(track.bearing_rad - bearing))
            range_err.append(abs(track.range_m - dist) / dist)
    # Found from the template alone (the whole-frame search spreads its scales over a few frames).
    first = states.index(TrackState.REACQUIRED)
    assert first < 3 and states[:first] == [TrackState.LOST] * first
    assert all(s is TrackState.TRACKING for s in states[first + 1 :])
    assert max(bearing_err) < math.radians(1.0)
    assert np.mean(range_err) < 0.05 and max(range_err) < 0.12


def test_lost_when_it_leaves_the_view_and_reacquired_when_it_comes_back() -> None:
    scene = world()
    template = render_target(scene, MOUNT)
    tracker = Tracker(template.image, CAMERA, height_m=template.height_m)
    x, y, th = behind_target(scene, 1.2)
    turn = [*[0.0] * 10, *np.linspace(0, math.radians(90), 10), *[math.radians(90)] * 20, *[0.0] * 10]
    states = [tracker.update(img, t).state for img, t, _, _ in frames(scene, ((x, y, th + a) for a in turn))]
    first = states.index(TrackState.REACQUIRED)
    assert first < 3 and states[first + 1 : 10] == [TrackState.TRACKING] * (9 - first)
    lost = [i for i, s in enumerate(states) if s is TrackState.LOST and i > first]
    assert lost and 10 < lost[0] < 20 and max(lost) < 45
    assert states[max(lost) + 1] is TrackState.REACQUIRED
    assert all(s is TrackState.TRACKING for s in states[max(lost) + 2 :])
    assert tracker.update(*next(frames(scene, iter([(x, y, th + 2.0)]), start_s=2.0))[:2]).lost_s == 0.0


def test_no_false_reacquisition_on_frames_without_the_target() -> None:
    scene = world()
    template = render_target(scene, MOUNT)
    tracker = Tracker(template.image, CAMERA, height_m=template.height_m)
    x, y, th = behind_target(scene, 1.2)
    away = [(x, y, th + math.pi + a) for a in np.linspace(-1.0, 1.0, 40)]  # look round the room
    tracks = [tracker.update(img, t) for img, t, _, _ in frames(scene, iter(away))]
    assert all(tr.state is TrackState.LOST for tr in tracks)
    assert tracks[-1].lost_s == pytest.approx(39 / 30)


def test_the_rotation_hint_keeps_a_fast_pan() -> None:
    """The robot spins 13 degrees per frame: the target jumps ~60 px, more than the search window.
    With the rotation passed in, the prediction follows it."""
    scene = world()
    template = render_target(scene, MOUNT)
    x, y, th = behind_target(scene, 1.5)
    pan = [th + math.radians(a) for a in (0, 0, 0, 13, 26, 13, 0, -13, -26)]  # held still to find it first
    for hinted in (False, True):
        tracker = Tracker(template.image, CAMERA, height_m=template.height_m)
        states = []
        prev = pan[0]
        for img, t, _, _ in frames(scene, ((x, y, a) for a in pan)):
            a = pan[len(states)]
            states.append(tracker.update(img, t, rotation_rad=(a - prev) if hinted else 0.0).state)
            prev = a
        found = states.index(TrackState.REACQUIRED)
        assert found < 3
        if hinted:
            assert states[found + 1 :] == [TrackState.TRACKING] * (len(pan) - found - 1)
        else:  # the jumps leave the search window: lost (or found again from scratch)
            assert any(s is not TrackState.TRACKING for s in states[3:])


def test_a_region_selected_in_a_frame() -> None:
    scene = world()
    pose = behind_target(scene, 1.0)
    seq = list(frames(scene, iter([pose] * 30)))
    first, _, bearing, dist = seq[0]
    # What a user drags round the target: its silhouette (the camera is at the target's mid-height).
    u, half = CAMERA.column(bearing), CAMERA.fx * 0.12 / (dist + 0.12)
    top, bottom = CAMERA.cy - CAMERA.fy * 0.17 / dist, CAMERA.cy + CAMERA.fy * 0.11 / dist
    tracker = Tracker.from_region(first, (u - half, top, 2 * half, bottom - top), CAMERA)
    for img, t, b, _ in seq[1:]:
        track = tracker.update(img, t)
        assert track.state is TrackState.TRACKING and track.range_m is None  # no size given: no range
        assert abs(track.bearing_rad - b) < math.radians(1.0)  # type: ignore[operator]


def textured(seed: int, h: int, w: int) -> np.ndarray:
    """An image full of corners: random rectangles and discs, each its own colour."""
    import cv2

    rng = np.random.default_rng(seed)
    img = np.full((h, w, 3), 128, dtype=np.uint8)
    for _ in range(40):
        colour = tuple(int(c) for c in rng.integers(0, 256, 3))
        x, y = int(rng.integers(0, w)), int(rng.integers(0, h))
        if rng.random() < 0.5:
            cv2.rectangle(img, (x, y), (x + int(rng.integers(4, 20)), y + int(rng.integers(4, 20))), colour, -1)
        else:
            cv2.circle(img, (x, y), int(rng.integers(3, 10)), colour, -1)
    return img


def test_feature_redetection_finds_a_textured_object_under_a_homography() -> None:
    """ORB features of the template, matched to the frame and a RANSAC homography: find_object_2d's
    method. The object appears at 80 % of its size, slightly turned, on a cluttered background."""
    import cv2

    template = textured(7, 90, 120)
    frame = textured(8, 240, 320)
    hom = np.array([[0.8, 0.05, 150.0], [-0.03, 0.8, 60.0], [0.0, 0.0, 1.0]])
    warped = cv2.warpPerspective(template, hom, (320, 240))
    mask = cv2.warpPerspective(np.full(template.shape[:2], 255, np.uint8), hom, (320, 240)) > 0
    frame[mask] = warped[mask]
    tracker = Tracker(template, CAMERA)
    assert tracker.has_features
    box = tracker._detect_features(frame)
    assert box is not None
    corners = cv2.perspectiveTransform(np.array([[[0, 0]], [[120, 0]], [[120, 90]], [[0, 90]]], np.float32), hom)
    x0, y0 = corners.reshape(-1, 2).min(axis=0)
    x1, y1 = corners.reshape(-1, 2).max(axis=0)
    assert box == pytest.approx((x0, y0, x1 - x0, y1 - y0), abs=3.0)
    track = tracker.update(frame, 0.0)
    assert track.state is TrackState.REACQUIRED and track.confidence > 0.72
    # The same frame without the object: nothing is found.
    assert Tracker(template, CAMERA).update(textured(8, 240, 320), 0.0).state is TrackState.LOST


def figure(h: int, w: int) -> tuple[np.ndarray, np.ndarray]:
    """A bottle-shaped object (a round head on a wider body) in magenta and yellow bands, with
    fine texture: its pixels and its mask (what is the object)."""
    import cv2

    rng = np.random.default_rng(5)
    img = np.zeros((h, w, 3), np.uint8)
    for i in range(6):  # bands, BGR
        img[i * h // 6 : (i + 1) * h // 6] = (200, 30, 200) if i % 2 else (30, 200, 220)
    img = np.clip(img.astype(np.int16) + rng.integers(-25, 26, (h, w, 1)), 0, 255).astype(np.uint8)
    mask = np.zeros((h, w), np.uint8)
    cv2.circle(mask, (w // 2, h // 5), w // 4, 255, -1)
    cv2.fillConvexPoly(mask, np.array([[w // 4, h // 3], [3 * w // 4, h // 3], [w - 1, h - 1], [0, h - 1]]), 255)
    return img, mask > 0


def test_a_cut_out_template_counts_only_the_object() -> None:
    """A photo with its background removed (BGRA): matched on the object's solid part, its colours
    measured over the object's own pixels, so the grey it was photographed on and the orange wall it
    now stands before count for nothing (counting them, the colours disagree and it is refused)."""
    import cv2

    body, mask = figure(96, 64)
    on_grey = np.where(mask[..., None], body, np.uint8(128))
    cut_out = np.dstack([on_grey, np.where(mask, 255, 0).astype(np.uint8)])
    rng = np.random.default_rng(6)
    wall = np.clip(np.array([40, 90, 170]) + rng.integers(-30, 31, (240, 320, 1)), 0, 255).astype(np.uint8)
    frame = wall.copy()
    small_body = cv2.resize(body, (32, 48), interpolation=cv2.INTER_AREA)
    small_mask = cv2.resize(mask.astype(np.uint8), (32, 48), interpolation=cv2.INTER_NEAREST) > 0
    frame[100:148, 200:232][small_mask] = small_body[small_mask]
    tracker = Tracker(cut_out, CAMERA)
    assert 0.5 <= tracker.look.core < 1.0  # the solid middle, not the head's corners
    assert all(mask[int(y), int(x)] for x, y in tracker._tpl_kp)  # features on the object only
    track = tracker.detect(frame, 0.0)
    assert track.state is TrackState.REACQUIRED and track.box is not None
    assert track.box == pytest.approx((200, 100, 32, 48), abs=3.0)
    with_mask = tracker.look.colour_match(frame, track.box)
    without = Tracker(on_grey, CAMERA, core=tracker.look.core).look.colour_match(frame, track.box)
    assert with_mask >= tracker.params.colour_redetect and with_mask > without + 0.1, (with_mask, without)
    # The same wall without the object: nothing is found.
    assert Tracker(cut_out, CAMERA).detect(wall, 0.0).state is TrackState.LOST


def test_a_cut_out_is_not_re_detected_on_a_look_alike_of_another_shape() -> None:
    """A cylinder painted in the figure's bands matches its solid middle as well as the figure
    does; the figure's head (where the cylinder has sky) or its surroundings (where a close,
    wide one has more bands) tell them apart."""
    import cv2

    body, mask = figure(96, 64)
    cut_out = np.dstack([np.where(mask[..., None], body, np.uint8(128)), np.where(mask, 255, 0).astype(np.uint8)])
    rng = np.random.default_rng(6)
    wall = np.clip(np.array([40, 90, 170]) + rng.integers(-30, 31, (240, 320, 1)), 0, 255).astype(np.uint8)
    wall[:90] = (210, 200, 190)  # sky above the wall

    def with_object(pixels: np.ndarray, where: np.ndarray, x: int, y: int) -> np.ndarray:
        frame = wall.copy()
        h, w = where.shape
        frame[y : y + h, x : x + w][where] = pixels[where]
        return frame

    small = cv2.resize(body, (40, 60), interpolation=cv2.INTER_AREA)
    small_mask = cv2.resize(mask.astype(np.uint8), (40, 60), interpolation=cv2.INTER_NEAREST) > 0
    the_figure = with_object(small, small_mask, 140, 80)
    headless = small_mask.copy()
    headless[: 60 // 3 - 2] = False  # the figure's body and shoulders, the wall where its head is
    no_head = with_object(small, headless, 140, 80)
    close = with_object(cv2.resize(body, (200, 220), interpolation=cv2.INTER_AREA), np.ones((220, 200), bool), 60, 10)
    assert Tracker(cut_out, CAMERA).detect(the_figure, 0.0).state is TrackState.REACQUIRED
    # Each check catches its own look-alike: the figure check the headless one (its surroundings
    # are the wall), the surround check the close one (its figure fits: stripes everywhere).
    tracker = Tracker(cut_out, CAMERA)
    assert tracker.detect(no_head, 0.0).state is TrackState.LOST
    assert tracker.look.surround_match(no_head, (140, 80, 40, 60)) <= tracker.params.surround_redetect
    tracker = Tracker(cut_out, CAMERA)
    assert tracker.detect(close, 0.0).state is TrackState.LOST


def test_a_cut_out_partly_off_the_picture_is_re_detected_by_what_is_in_it() -> None:
    """A close target at the side of the view (a quarter of its box past the frame's edge): its
    figure is checked over the part in the picture, so it is found; a headless look-alike at the
    same place is still refused; with less than FIGURE_SEEN of the figure in, nothing is; and a box
    past the top edge is not judged (the head, which a look-alike lacks, is what is lost there)."""
    import cv2

    body, mask = figure(96, 64)
    cut_out = np.dstack([np.where(mask[..., None], body, np.uint8(128)), np.where(mask, 255, 0).astype(np.uint8)])
    rng = np.random.default_rng(6)
    wall = np.clip(np.array([40, 90, 170]) + rng.integers(-30, 31, (240, 320, 1)), 0, 255).astype(np.uint8)
    wall[:60] = (210, 200, 190)
    w, h = 80, 120
    big = cv2.resize(body, (w, h), interpolation=cv2.INTER_AREA)
    big_mask = cv2.resize(mask.astype(np.uint8), (w, h), interpolation=cv2.INTER_NEAREST) > 0

    def at_right_edge(where: np.ndarray, past: int) -> np.ndarray:
        frame = wall.copy()
        x = 320 - w + past
        frame[60 : 60 + h, x:320][where[:, : w - past]] = big[:, : w - past][where[:, : w - past]]
        return frame

    track = Tracker(cut_out, CAMERA).detect(at_right_edge(big_mask, w // 4), 0.0)
    assert track.state is TrackState.REACQUIRED and track.box is not None
    assert track.box == pytest.approx((320 - w + w // 4, 60, w, h), abs=6.0)
    headless = big_mask.copy()
    headless[: h // 3 - 3] = False
    assert Tracker(cut_out, CAMERA).detect(at_right_edge(headless, w // 4), 0.0).state is TrackState.LOST
    assert Tracker(cut_out, CAMERA).detect(at_right_edge(big_mask, w // 2 + 8), 0.0).state is TrackState.LOST
    # Past the top edge the head is what is lost: a headless look-alike or a striped block there,
    # whose bodies fit the figure's, are not taken.
    block = np.zeros_like(big_mask)
    block[:, 12:68] = True
    for look_alike in (headless, block):
        top = np.clip(np.array([40, 90, 170]) + rng.integers(-30, 31, (240, 320, 1)), 0, 255).astype(np.uint8)
        top[0 : h - 30, 120 : 120 + w][look_alike[30:]] = big[30:][look_alike[30:]]
        assert Tracker(cut_out, CAMERA).detect(top, 0.0).state is TrackState.LOST


def test_a_cut_out_track_that_slid_onto_a_look_alike_is_dropped() -> None:
    """The figure walks behind a wide cylinder painted in its bands: its solid middle matches the
    cylinder as well as the figure, so the match slides onto the cylinder and holds there. The
    figure's outline does not fit (bands where its head's surroundings should be): after `misfit_s`
    the track is dropped, and the cylinder is not re-detected. A look-alike only behind the figure
    for less than `misfit_s` does not drop it."""
    import cv2

    from host_sdk.perception.tracker_params import TrackerParams

    body, mask = figure(96, 64)
    cut_out = np.dstack([np.where(mask[..., None], body, np.uint8(128)), np.where(mask, 255, 0).astype(np.uint8)])
    rng = np.random.default_rng(6)
    wall = np.clip(np.array([40, 90, 170]) + rng.integers(-30, 31, (240, 320, 1)), 0, 255).astype(np.uint8)
    wall[:90] = (210, 200, 190)
    small = cv2.resize(body, (40, 60), interpolation=cv2.INTER_AREA)
    small_mask = cv2.resize(mask.astype(np.uint8), (40, 60), interpolation=cv2.INTER_NEAREST) > 0
    cylinder = cv2.resize(body, (90, 60), interpolation=cv2.INTER_AREA)

    def frame(*, cylinder_in_front: bool, cylinder_behind: bool) -> np.ndarray:
        img = wall.copy()
        if cylinder_behind:
            img[80:140, 115:205] = cylinder
        img[80:140, 140:180][small_mask] = small[small_mask]
        if cylinder_in_front:
            img[80:140, 115:205] = cylinder
        return img

    learnt: list[np.ndarray] = []

    def run(params: TrackerParams, script: list[tuple[bool, bool]]) -> list[TrackState]:
        tracker = Tracker(cut_out, CAMERA, params=params)
        states = []
        for i, (front, behind) in enumerate(script):
            states.append(tracker.update(frame(cylinder_in_front=front, cylinder_behind=behind), i / 30).state)
            learnt.append(tracker.look.current.copy())
        return states

    p = TrackerParams()
    alone = [(False, False)] * 15
    hidden = alone + [(True, False)] * round(30 * (p.misfit_s + 1.5))
    states = run(p, hidden)
    assert states[14] is TrackState.TRACKING
    dropped = states.index(TrackState.LOST, 15)
    assert 15 + round(30 * p.misfit_s) <= dropped <= 15 + round(30 * p.misfit_s) + p.lost_after, states
    assert set(states[dropped:]) == {TrackState.LOST}, states  # and the cylinder is not taken for it
    # What the track saw on the cylinder did not teach the adaptive template anything.
    assert all(np.array_equal(learnt[16], later) for later in learnt[17:dropped]), "learnt from a misfit"
    # Without the check, the track stays on the cylinder (and learns from it).
    learnt.clear()
    unchecked = run(TrackerParams(figure_keep=0.0, surround_keep=1.0), hidden)
    assert unchecked[-1] is TrackState.TRACKING
    assert not np.array_equal(learnt[16], learnt[-1])
    # In front of the cylinder briefly, the figure is kept.
    passing = alone + [(False, True)] * round(30 * p.misfit_s * 0.6) + alone
    assert set(run(p, passing)[14:]) == {TrackState.TRACKING}
    assert TrackState.LOST in run(TrackerParams(misfit_s=0.1), passing)  # it does not fit the figure there


def test_a_plain_cut_out_has_no_figure_to_check() -> None:
    """The figure check correlates a cut-out's own pattern; a plain object (a red cup, shaded)
    has none, and correlating it would correlate noise: the check is skipped (1.0), where a
    patterned figure's is not."""
    import cv2

    h, w = 90, 60
    mask = np.zeros((h, w), np.uint8)
    cv2.ellipse(mask, (w // 2, h // 2), (w // 2 - 2, h // 2 - 2), 0, 0, 360, 255, -1)
    shade = np.linspace(1.0, 0.9, w, dtype=np.float32)[None, :, None]
    cup = (np.full((h, w, 3), (40, 40, 200), np.float32) * shade).astype(np.uint8)
    wall = np.full((240, 320, 3), 128, np.uint8)
    assert Tracker(np.dstack([cup, mask]), CAMERA).look.figure_match(wall, (100, 60, 40, 60)) == 1.0
    body, figure_mask = figure(96, 64)
    patterned = np.dstack([body, np.where(figure_mask, 255, 0).astype(np.uint8)])
    assert Tracker(patterned, CAMERA).look.figure_match(wall, (100, 60, 40, 60)) < 0.5


def test_template_files(tmp_path: Path) -> None:
    """A PNG with its background transparent gives a cut-out; an opaque alpha, grey or 16-bit file
    a plain BGR template; anything else an error naming the file."""
    import cv2

    body, mask = figure(96, 64)
    cv2.imwrite(str(tmp_path / "cut.png"), np.dstack([body, np.where(mask, 255, 0).astype(np.uint8)]))
    cv2.imwrite(str(tmp_path / "opaque.png"), np.dstack([body, np.full(mask.shape, 255, np.uint8)]))
    cv2.imwrite(str(tmp_path / "grey.png"), body[..., 1])
    cv2.imwrite(str(tmp_path / "deep.png"), body.astype(np.uint16) * 257)
    (tmp_path / "notes.txt").write_text("not an image")
    cut = read_template(tmp_path / "cut.png")
    assert cut.shape == (96, 64, 4) and np.array_equal(cut[..., 3] == 255, mask)
    assert Tracker(cut, CAMERA).look.mask is not None
    assert read_template(tmp_path / "opaque.png").shape == (96, 64, 3)
    assert read_template(tmp_path / "grey.png").shape == (96, 64, 3)
    deep = read_template(tmp_path / "deep.png")
    assert deep.dtype == np.uint8 and np.array_equal(deep, body)
    with pytest.raises(CommandRangeError, match=r"notes\.txt"):
        read_template(tmp_path / "notes.txt")
    empty = np.dstack([body, np.zeros(mask.shape, np.uint8)])
    with pytest.raises(CommandRangeError, match="0 % opaque"):  # all background: nothing to track
        Tracker(empty, CAMERA)


def test_cut_out_core() -> None:
    _, mask = figure(96, 64)
    core = cutout_core(mask)
    h, w = mask.shape
    dx, dy = round(w * (1 - core) / 2), round(h * (1 - core) / 2)
    assert mask[dy : h - dy, dx : w - dx].mean() >= 0.9
    assert cutout_core(np.ones((40, 30), bool)) == 1.0
    assert cutout_core(np.zeros((40, 30), bool)) == 0.2


def test_a_coloured_object_lit_from_the_side_is_still_found() -> None:
    """Photographed in even light, met with the light from one side (its far half at a third of
    the brightness): its grey pattern is not what the photo shows, its colours' shares are. Grey or
    BGR correlation refuses it (below accept_redetect); grey plus shares keeps it."""
    import cv2

    body, _ = figure(96, 64)
    rng = np.random.default_rng(9)
    frame = np.clip(np.array([120, 125, 130]) + rng.integers(-40, 41, (240, 320, 1)), 0, 255).astype(np.uint8)
    seen = cv2.resize(body, (40, 60), interpolation=cv2.INTER_AREA).astype(np.float32)
    seen *= np.linspace(1.0, 0.33, 40, dtype=np.float32)[None, :, None] ** 1.5
    frame[90:150, 150:190] = seen.astype(np.uint8)
    tracker = Tracker(body, CAMERA)
    track = tracker.detect(frame, 0.0)
    assert track.state is TrackState.REACQUIRED and track.box is not None, track
    assert iou(track.box, (150, 90, 40, 60)) > 0.75, track.box
    bgr = cv2.matchTemplate(frame[90:150, 150:190], cv2.resize(body, (40, 60)), cv2.TM_CCOEFF_NORMED)
    assert float(bgr.max()) < tracker.params.accept_redetect  # what plain BGR correlation scores
    assert tracker.look.chroma_weight == 1.0  # a pattern of two paints: the shares carry it


def test_a_grey_object_keeps_grey_in_charge() -> None:
    grey_cup = np.repeat(textured(3, 60, 40).mean(axis=2, keepdims=True), 3, axis=2).astype(np.uint8)
    grey_cup[..., 2] = np.clip(grey_cup[..., 2].astype(np.int16) + 6, 0, 255).astype(np.uint8)  # a warm tint
    assert Tracker(grey_cup, CAMERA).look.chroma_weight < 0.2


def test_an_absurd_box_is_dropped_not_allocated() -> None:
    """A homography from a few clustered feature matches can throw a box kilometres wide; matching
    round it would pad the window to gigabytes (cv2.error). It is not an object: nothing found."""
    tracker = Tracker(textured(7, 90, 120), CAMERA)
    frame = textured(8, 240, 320)
    for box in ((-5000.0, -8000.0, 20000.0, 30000.0), (400.0, 10.0, 40.0, 40.0), (10.0, 10.0, 1.0, 900.0)):
        assert tracker._match_near(frame, box) is None


def test_camera_model_geometry() -> None:
    cam = CameraModel.pi_camera_v2(320, 240)
    assert cam.fx == pytest.approx(160 / math.tan(math.radians(31.1)))
    assert cam.bearing(cam.cx) == 0.0 and cam.bearing(0) > 0  # left of centre is left of the robot
    assert cam.column(cam.bearing(42.0)) == pytest.approx(42.0)
    assert cam.range_from_size(h_px=cam.fy * 0.3 / 2.0, height_m=0.3) == pytest.approx(2.0)
    assert cam.range_from_size(h_px=50) is None
    x, y = CameraModel.pi_camera_v2(mount_x_m=0.3).point(math.radians(30), 1.0)
    assert (x, y) == pytest.approx((0.3 + 1.0, 1.0 * math.tan(math.radians(30))))


def test_bad_templates_and_regions_are_refused() -> None:
    with pytest.raises(CommandRangeError, match="template"):
        Tracker(np.zeros((20, 20), dtype=np.uint8), CAMERA)
    with pytest.raises(CommandRangeError, match="template"):
        Tracker(np.zeros((3, 20, 3), dtype=np.uint8), CAMERA)
    with pytest.raises(CommandRangeError, match="BGRA cut-out"):
        Tracker(np.zeros((20, 20, 2), dtype=np.uint8), CAMERA)
    with pytest.raises(CommandRangeError, match="box"):
        Tracker.from_region(np.zeros((240, 320, 3), dtype=np.uint8), (300, 10, 40, 40), CAMERA)
    with pytest.raises(CommandRangeError, match="fx"):
        CameraModel(320, 240, 0.0, 1.0, 0, 0)


def test_a_one_shot_detection_tries_every_scale() -> None:
    """`detect` finds the target in one frame at any distance (`update` spreads its scales over frames)."""
    scene = world()
    template = render_target(scene, MOUNT)
    for back in (1.0, 2.5):
        image, t, bearing, _ = next(frames(scene, iter([behind_target(scene, back)])))
        tracker = Tracker(template.image, CAMERA, height_m=template.height_m)
        track = tracker.detect(image, t)
        assert track.state is TrackState.REACQUIRED
        assert abs(track.bearing_rad - bearing) < math.radians(1.0)  # type: ignore[operator]
