"""The tracker on sequences built from real photographs (tests/support/photo_sequences.py): a cut-out
object whose box holds background, a cluttered real scene, pan, scale, rotation, exposure, a pole in
front, out of the picture and back, JPEG q60. Seeded: the same frames every run.

The floors sit a little below what the tracker does (benchmarks/tracking.py prints it), on the set
it was tuned on (scikit-image's photographs) and on the held-out set (OpenCV's, Debian's opencv-doc),
which no parameter was chosen on; docs/autonomy.md has the table."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from host_sdk.body import CameraModel
from host_sdk.errors import CommandRangeError
from host_sdk.perception.tracking import Track, Tracker, TrackState
from tests.support.photo_sequences import SPECS as PHOTO_SPECS
from tests.support.photo_sequences import Sequence, build, iou

CAMERA = CameraModel.pi_camera_v2(320, 240)
FLOORS = {
    "slide": 0.97,
    "easy": 0.8,
    "medium": 0.75,
    "hard": 0.78,
    "small-plain": 0.85,
    "small-textured": 0.85,
    # The held-out set (OpenCV's photographs): no parameter was chosen on these.
    "held-slide": 0.97,
    "held-easy": 0.85,
    "held-medium": 0.8,
    "held-hard": 0.78,
    "held-small-plain": 0.85,
    "held-small-textured": 0.85,
}


@pytest.fixture(scope="module")
def runs() -> dict[str, tuple[Sequence, list[Track]]]:
    import cv2

    cv2.setNumThreads(1)
    out = {}
    for spec in PHOTO_SPECS:
        if spec.name not in FLOORS:
            continue
        seq = build(spec)
        first = seq.frames[0]
        assert first.box is not None
        tracker = Tracker.from_region(first.image, first.box, CAMERA)
        out[spec.name] = (seq, [tracker.update(f.image, f.time_s) for f in seq.frames[1:]])
    return out


@pytest.mark.parametrize("name", list(FLOORS))
def test_keeps_the_object_while_it_is_in_view(runs: dict[str, tuple[Sequence, list[Track]]], name: str) -> None:
    seq, tracks = runs[name]
    truth = [f.box for f in seq.frames[1:]]
    view = [i for i, b in enumerate(truth) if b is not None]
    kept = sum(iou(tracks[i].box, truth[i]) >= 0.5 for i in view) / len(view)
    assert kept >= FLOORS[name], f"{name}: kept {kept:.2f}"


@pytest.mark.parametrize("name", [s.name for s in PHOTO_SPECS if s.out is not None and s.name in FLOORS])
def test_never_found_out_of_view_and_reacquired_on_return(
    runs: dict[str, tuple[Sequence, list[Track]]], name: str
) -> None:
    seq, tracks = runs[name]
    truth = [f.box for f in seq.frames[1:]]
    out = [i for i, b in enumerate(truth) if b is None]
    assert out, "the sequence takes the object out of the picture"
    # Nothing on the background passes for it (a target still partly in the picture as it leaves,
    # under the truth's 30 %, may still be tracked: it is there).
    assert [i for i in out if tracks[i].found and seq.frames[i + 1].visible < 0.1] == []
    assert all(tracks[i].state is TrackState.LOST for i in out[3:])
    back = max(out) + 1
    held = [i for i in range(back, len(truth)) if iou(tracks[i].box, truth[i]) >= 0.5]
    assert held and held[0] - back <= 10, f"{name}: reacquired {held[0] - back if held else 'never'} frames after"
    assert tracks[held[0]].state in (TrackState.REACQUIRED, TrackState.TRACKING)
    # and it holds on afterwards
    assert len(held) >= 0.8 * (len(truth) - held[0])


def test_a_plain_object_found_again_after_a_pole_comes_back_at_its_size() -> None:
    """The small plain cup is lost behind the pole and found again while the pole still hides part
    of it: on the visible part, about half its size (a plain object's part correlates almost as well
    as all of it). Once the pole has passed, its box is the cup's size again, within 15 %."""
    import cv2

    cv2.setNumThreads(1)
    spec = next(s for s in PHOTO_SPECS if s.name == "small-plain")
    seq = build(dataclasses.replace(spec, frames=75, out=None))  # the pole passes over frames 40-55
    first = seq.frames[0]
    assert first.box is not None
    tracker = Tracker.from_region(first.image, first.box, CAMERA)
    tracks = [tracker.update(f.image, f.time_s) for f in seq.frames[1:]]
    assert TrackState.LOST in [t.state for t in tracks[40:56]]
    sides = []
    for track, frame in zip(tracks[59:], seq.frames[60:], strict=True):
        assert track.found and track.box is not None and frame.box is not None
        sides += [track.box[2] / frame.box[2], track.box[3] / frame.box[3]]
    assert min(sides) >= 0.85 and max(sides) <= 1.15, f"sides {min(sides):.2f}..{max(sides):.2f} of the truth's"


def test_a_plain_core_is_widened_to_the_object_edges() -> None:
    """A plain object's centre has nothing to correlate: the matched part grows until it holds
    the object's outline."""
    frame = np.full((240, 320, 3), 90, np.uint8)
    frame[100:140, 140:190] = (30, 40, 200)  # a plain red box
    tracker = Tracker.from_region(frame, (130, 90, 70, 60), CAMERA)
    assert tracker.look.core > 0.6
    moved = np.full((240, 320, 3), 90, np.uint8)
    moved[104:144, 146:196] = (30, 40, 200)
    track = tracker.update(moved, 1 / 30)
    assert track.state is TrackState.TRACKING
    assert track.box is not None and track.box[:2] == pytest.approx((136, 94), abs=1.5)


def test_the_core_share_is_checked() -> None:
    with pytest.raises(CommandRangeError, match="core"):
        Tracker(np.zeros((40, 40, 3), np.uint8), CAMERA, core=0.1)
