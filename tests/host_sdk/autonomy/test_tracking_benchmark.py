"""The tracking benchmark's figures (benchmarks/tracking.py, tracking_metrics.py) on tiny inputs whose
answers are known, and the photo sequences' visible share it counts accuracy over."""

from __future__ import annotations

import numpy as np
import pytest
import tracking as bench  # benchmarks/ is on pytest's pythonpath
from tracking_metrics import Step, Truth, score
from tracking_scenes import Scene, Shot

from host_sdk.body import CameraModel
from tests.support.photo_sequences import SPECS, build

BOX = (100.0, 80.0, 40.0, 20.0)  # larger side 40: a centre within 10 px is accurate


def _moved(dx: float) -> tuple[float, float, float, float]:
    return (BOX[0] + dx, *BOX[1:])


def test_false_found_counts_only_the_frames_out_of_the_picture() -> None:
    truth = [Truth(BOX, 1.0), Truth(BOX, 1.0), Truth(None, 0.0), Truth(None, 0.1), Truth(BOX, 1.0)]
    always = [Step(BOX, False, 0.001)] * 5
    s = score("t", "always", truth, always, 30.0)
    assert (s.false_found, s.out_of_view) == (2, 2)
    honest = [
        Step(BOX, False, 0.001),
        Step(BOX, False, 0.001),
        Step(None, True, 0.01),
        Step(None, True, 0.01),
        Step(BOX, True, 0.01),
    ]
    assert score("t", "honest", truth, honest, 30.0).false_found == 0
    assert score("t", "honest", truth[:2], honest[:2], 30.0).meets("false_found") is None  # never out


def test_accuracy_is_the_centre_within_a_quarter_of_the_larger_side_over_frames_mostly_in_view() -> None:
    truth = [Truth(BOX, 1.0), Truth(BOX, 1.0), Truth(BOX, 0.9), Truth(BOX, 0.5), Truth(BOX, 0.8), Truth(BOX, 1.0)]
    steps = [
        Step(None, False, 0.0),  # the start frame: not counted
        Step(_moved(9.9), False, 0.001),  # accurate
        Step(_moved(10.5), False, 0.001),  # a quarter of 40 is 10: not accurate
        Step(None, True, 0.001),  # half hidden: not counted
        Step(None, True, 0.001),  # 80 % in view and lost: counted, a miss
        Step(BOX, False, 0.001),
    ]
    s = score("t", "x", truth, steps, 30.0)
    assert s.counted == 4
    assert s.accuracy == pytest.approx(2 / 4)


def test_reacquire_runs_from_the_full_return_at_the_scenes_frame_rate() -> None:
    back = [Truth(BOX, 1.0), Truth(None, 0.0), Truth(None, 0.2), Truth(BOX, 0.5), Truth(BOX, 1.0)]
    truth = back + [Truth(BOX, 1.0)] * 5
    lost = [Step(None, True, 0.02)] * 7
    held = [Step(BOX, False, 0.004)] * 3
    s = score("t", "x", truth, lost + held, 10.0)
    assert (s.returns, s.reacquire_s) == (1, pytest.approx(0.3))  # frame 4 fully back, frame 7 held
    assert s.meets("reacquire_s") is True
    never = score("t", "x", truth, [Step(None, True, 0.02)] * 10, 10.0)
    assert never.reacquire_s is None and never.meets("reacquire_s") is False
    assert (s.fps_tracking, s.tracking_frames) == (pytest.approx(250.0), 3)
    assert (s.fps_searching, s.searching_frames) == (pytest.approx(50.0), 6)  # the start frame is not timed
    assert s.meets("fps_tracking") is True and s.meets("fps_searching") is True


def test_the_photo_sequences_say_how_much_of_the_target_is_in_view() -> None:
    spec = SPECS[1]
    assert spec.occlusion is not None and spec.out is not None
    seq = build(spec)
    start, length, _ = spec.occlusion
    assert min(f.visible for f in seq.frames[start : start + length]) < 0.7  # the pole hides part of it
    assert all(f.visible > 0.99 for f in seq.frames[:start])
    gone = [f for f in seq.frames if f.box is None]
    assert gone and all(f.visible < 0.3 for f in gone)


def _scene() -> Scene:
    """A textured square that leaves the picture for three frames and comes back."""
    rng = np.random.default_rng(1)
    patch = rng.integers(0, 255, (40, 40, 3), dtype=np.uint8)
    shots = []
    for i in range(12):
        image = np.full((240, 320, 3), 100, np.uint8)
        box = None if 5 <= i < 8 else (120.0 + 2 * i, 100.0, 40.0, 40.0)
        if box is not None:
            x, y = round(box[0]), round(box[1])
            image[y : y + 40, x : x + 40] = patch
        shots.append(Shot(image, i / 30, box, 0.0 if box is None else 1.0))
    return Scene("square", "photos", tuple(shots), CameraModel.pi_camera_v2(320, 240))


def test_every_tracker_runs_and_is_scored_over_a_scene() -> None:
    """The harness, not the trackers' quality (the tracker's own tests hold that)."""
    scene = _scene()
    scores, _ = bench.measure([scene], repeat=1, seed=1)
    names = [s.tracker for s in scores]
    assert names[0] == "RoverLink" and "MIL" in names and names[-1] == "features+homography"
    for s in scores:
        assert (s.counted, s.out_of_view, s.returns) == (8, 3, 1)
        assert s.tracking_frames + s.searching_frames == 11
        assert s.accuracy is not None and 0.0 <= s.accuracy <= 1.0


def test_a_tracker_that_always_answers_is_charged_for_every_frame_out_of_view() -> None:
    scene = _scene()

    def truth_or_last(_: Scene) -> bench.Update:
        last = [scene.shots[0].box]

        def update(image: np.ndarray, time_s: float) -> tuple[bench.Box | None, bool]:
            box = scene.shots[round(time_s * 30)].box or last[0]  # holds on to the last box, as MIL does
            last[0] = box
            return box, False

        return update

    steps = bench.steps(scene, truth_or_last, repeat=2)
    s = score(scene.name, "stub", [Truth(f.box, f.visible) for f in scene.shots], steps, scene.fps)
    assert (s.false_found, s.accuracy, s.reacquire_s, s.searching_frames) == (3, 1.0, 0.0, 0)
