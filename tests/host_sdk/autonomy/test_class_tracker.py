"""Following a face through a real photo panned out of the picture and back: the detector picks it,
the tracker follows it, loses it, and the detector finds it again; through the follow behaviour's
pilot, whose target state goes LOST and back."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest
from numpy.typing import NDArray

from host_sdk.autonomy import Follower, FollowPilot
from host_sdk.errors import CommandRangeError
from host_sdk.perception import CameraModel, Footprint, ScanFilter
from host_sdk.perception.class_tracker import ClassTracker, ClassTrackerParams
from host_sdk.perception.detectors import iou
from host_sdk.perception.tracker_params import TrackerParams
from host_sdk.perception.tracking import TrackState
from host_sdk.pose import Pose
from host_sdk.sensors import CameraFrame
from tests.host_sdk.autonomy.photos import FACES, PERSONS, needs_detectors, photo

pytestmark = needs_detectors

CAMERA = CameraModel.pi_camera_v2(320, 240, mount_x_m=0.1)
FPS = 15.0
FACE = FACES["astronaut_collins"]


def panorama() -> NDArray[np.uint8]:
    """The astronaut's portrait with the coffee photo beside it: a real scene to pan across."""
    import cv2

    face, other = photo("astronaut_collins"), photo("coffee_cup")
    other = cv2.resize(other, (other.shape[1] * 512 // other.shape[0], 512), interpolation=cv2.INTER_AREA)
    return np.ascontiguousarray(np.hstack([face, other]))


def pan(offsets: list[int]) -> Iterator[tuple[NDArray[np.uint8], float, int]]:
    """(320 x 240 frame, time, left edge in the panorama) as the camera pans across it."""
    scene = panorama()
    for i, x0 in enumerate(offsets):
        yield np.ascontiguousarray(scene[0:240, x0 : x0 + 320]), i / FPS, x0


OUT_AND_BACK = list(range(60, 700, 20)) + list(range(700, 60, -20)) + [60] * 10
"""The face is whole in the picture up to x0 = 174, gone past 272 (for about 3 s), whole again."""


def truth(x0: int) -> tuple[float, float, float, float]:
    return FACE[0] - x0, FACE[1], FACE[2], FACE[3]


def run_pilot(tracker: ClassTracker) -> list[tuple[TrackState, float | None, int]]:
    """The pilot's target state per frame, with the box's overlap with the hand-measured face."""
    pilot = FollowPilot(ScanFilter(), tracker, Follower(Footprint(0.12, 0.03), CAMERA))
    seen = []
    for image, t, x0 in pan(OUT_AND_BACK):
        pilot.on_frame(CameraFrame(image, t, int(t * FPS)), Pose(0.0, 0.0, 0.0, time_s=t))
        track = pilot.last_track
        assert track is not None
        overlap = None if track.box is None else iou(track.box, truth(x0))
        seen.append((track.state, overlap, x0))
    return seen


def check_out_and_back(seen: list[tuple[TrackState, float | None, int]]) -> None:
    states = [s for s, _, _ in seen]
    # Found on the first frame (the detector), on the face.
    assert states[0] is TrackState.REACQUIRED and seen[0][1] is not None and seen[0][1] >= 0.5
    # Tracked on the face while it is whole in the picture on the way out...
    out = [ov for s, ov, x0 in seen[: len(OUT_AND_BACK) // 2] if x0 <= 160]
    assert all(ov is not None and ov >= 0.5 for ov in out), out
    # ...lost once it has left (nothing else in the picture is taken for it)...
    gone = [s for s, _, x0 in seen if x0 >= 300]
    assert gone and all(s is TrackState.LOST for s in gone)
    # ...and found again, on the face, once it is back.
    back = seen[len(OUT_AND_BACK) // 2 :]
    again = next(i for i, (s, _, _) in enumerate(back) if s is not TrackState.LOST)
    assert back[again][0] is TrackState.REACQUIRED
    # Whole again from x0 = 174: found within the detector's period (3 frames) of that, if not
    # earlier by the tracker's own re-detection of the part in view.
    assert back[again][2] > 174 - 3 * 20, f"found again only at x0 = {back[again][2]}"
    assert all(ov is not None and ov >= 0.5 for _, ov, _ in back[again:]), back[again:]


def test_a_face_panned_out_of_the_picture_and_back_is_lost_and_found_again() -> None:
    tracker = ClassTracker("face", CAMERA)
    check_out_and_back(run_pilot(tracker))
    # The detector ran at most at its rate while the face was away (it costs tens of ms).
    lost_s = sum(1 for x0 in OUT_AND_BACK if x0 > 272) / FPS
    assert tracker.detector_runs <= 2 + lost_s / tracker.params.detect_every_s


def test_the_detector_finds_it_again_when_the_template_does_not() -> None:
    """With the tracker's own re-detection off (no correlation reaches 1.01), only the face detector
    can bring the target back: it must, at the face (the box nearest the last one seen)."""
    tracker = ClassTracker("face", CAMERA, tracker_params=TrackerParams(accept_redetect=1.01))
    seen = run_pilot(tracker)
    check_out_and_back(seen)
    assert tracker.acquisitions == 2  # at the start, and once back


def test_a_person_picked_among_two_is_followed_as_the_camera_pans() -> None:
    """Real pedestrians side by side: the detector's pick (the more central) is the one the tracker
    then holds while the view pans 80 pixels, never the other person."""
    import cv2

    scene = cv2.resize(photo("pedestrians_f050"), (400, 300), interpolation=cv2.INTER_CUBIC)
    picked, other = ([v * 1.25 for v in p] for p in PERSONS["pedestrians_f050"])
    tracker = ClassTracker("person", CAMERA)
    for i, x0 in enumerate(range(0, 84, 4)):
        frame = np.ascontiguousarray(scene[30:270, x0 : x0 + 320])
        track = tracker.update(frame, i / FPS)
        assert track.found and track.box is not None, (i, track)
        cx = track.box[0] + track.box[2] / 2
        centres = [p[0] + p[2] / 2 - x0 for p in (picked, other)]
        assert abs(cx - centres[0]) < picked[2] / 2 < abs(cx - centres[1]), (i, track.box, centres)
    assert tracker.acquisitions == 1 and tracker.kind == "person"


def test_range_from_the_kinds_height() -> None:
    image, t, _ = next(pan([100]))
    tracker = ClassTracker("face", CAMERA)
    track = tracker.update(image, t)
    assert track.state is TrackState.REACQUIRED and track.box is not None and track.range_m is not None
    # depth = fy * 0.16 m / box height, along a ray a little off the axis
    assert track.range_m == pytest.approx(CAMERA.fy * 0.16 / track.box[3], rel=0.05)
    taller = ClassTracker("face", CAMERA, height_m=0.32).update(image, t)
    assert taller.range_m == pytest.approx(2 * track.range_m, rel=0.01)


def test_nobody_in_the_picture_is_lost_with_the_time_since_the_start() -> None:
    tracker = ClassTracker("face", CAMERA, params=ClassTrackerParams(detect_every_s=0.2))
    scene = photo("coffee_cup")[0:240, 0:320].copy()
    tracks = [tracker.update(scene, i / FPS) for i in range(8)]
    assert all(tr.state is TrackState.LOST and tr.box is None for tr in tracks)
    assert tracks[-1].lost_s == pytest.approx(7 / FPS)
    assert tracker.detector_runs == 3  # at 0, 0.2 and 0.4 s: not every frame


def test_bad_arguments_name_the_field() -> None:
    with pytest.raises(CommandRangeError, match="kind"):
        ClassTracker("dog", CAMERA)
    with pytest.raises(CommandRangeError, match="height_m"):
        ClassTracker("face", CAMERA, height_m=0.0)
    with pytest.raises(CommandRangeError, match="redetect_after_s"):
        ClassTrackerParams(redetect_after_s=-1.0)
