"""The person and face detectors on real photographs (not the emulator's renderer), and the rules
that choose among their boxes."""

from __future__ import annotations

import os
import sys

import numpy as np
import pytest

from host_sdk.errors import CommandRangeError
from host_sdk.perception.detectors import (
    TARGET_HEIGHT_M,
    Detection,
    DetectorParams,
    detector_for,
    iou,
    nms,
    pick,
)
from tests.host_sdk.autonomy.photos import FACES, PERSONS, needs_detectors, photo


@needs_detectors
@pytest.mark.parametrize("name", sorted(FACES))
@pytest.mark.parametrize("work_width", [320, 640])
def test_finds_the_face_in_a_portrait(name: str, work_width: int) -> None:
    image = photo(name)
    found = detector_for("face", DetectorParams(work_width=work_width)).detect(image)
    assert found, f"no face found in {name}"
    best = pick(found, image.shape)
    assert best is not None and best.kind == "face"
    assert iou(best.box, FACES[name]) >= 0.5, (best.box, FACES[name])
    # Everything else found in a one-person portrait would be a false face.
    assert len(found) == 1, found


@needs_detectors
@pytest.mark.parametrize("name", ["coffee_cup", "rocket_launch"])
def test_no_face_in_photos_without_people(name: str) -> None:
    assert detector_for("face").detect(photo(name)) == []


@needs_detectors
@pytest.mark.parametrize("name", ["coffee_cup", "rocket_launch", "astronaut_collins", "grace_hopper"])
@pytest.mark.parametrize("work_width", [320, 640])
def test_no_person_where_there_is_no_whole_body(name: str, work_width: int) -> None:
    """HOG finds upright whole bodies: a head-and-shoulders portrait is not one (the honest answer is
    nobody), and at full resolution its SVM scores a helmet and a launch gantry 0.6-0.75, which the
    default threshold rejects."""
    assert detector_for("person", DetectorParams(work_width=work_width)).detect(photo(name)) == []


def _on(box: tuple[float, ...], person: tuple[float, float, float, float]) -> bool:
    """A HOG box on a hand-measured person: round the person's centre, a margin above and below
    (the people detector's window is 64 x 128 round a body about 96 high)."""
    x, y, w, h = box
    cx, cy = person[0] + person[2] / 2, person[1] + person[3] / 2
    return x <= cx <= x + w and y <= cy <= y + h and 1.0 <= h / person[3] <= 1.6


@needs_detectors
@pytest.mark.parametrize("name", sorted(PERSONS))
@pytest.mark.parametrize("scale", [1, 2])
def test_finds_each_whole_person_and_nothing_else(name: str, scale: int) -> None:
    """Real pedestrians (a street camera's frames), at 320 x 240 and at 640 x 480 reduced to the
    detector's working width: each person found, every box on a person."""
    import cv2

    image = photo(name)
    if scale > 1:
        image = cv2.resize(image, None, fx=scale, fy=scale, interpolation=cv2.INTER_CUBIC)
    found = detector_for("person").detect(image)
    people = [tuple(v * scale for v in p) for p in PERSONS[name]]
    for person in people:
        assert any(_on(d.box, person) for d in found), (name, person, found)  # type: ignore[arg-type]
    assert all(any(_on(d.box, p) for p in people) for d in found), found  # type: ignore[arg-type]


@needs_detectors
def test_picks_the_more_central_of_two_people_of_one_size() -> None:
    image = photo("pedestrians_f050")
    best = pick(detector_for("person").detect(image), image.shape)
    near_centre, off_centre = PERSONS["pedestrians_f050"]
    assert best is not None and _on(best.box, near_centre) and not _on(best.box, off_centre)


def test_nms_keeps_the_best_of_overlapping_boxes_and_drops_nested_ones() -> None:
    boxes = np.array([[10, 10, 50, 100], [14, 12, 50, 100], [200, 10, 40, 80], [20, 20, 20, 30]], dtype=np.float64)
    scores = np.array([1.0, 2.0, 0.5, 3.0])
    # The small box (best score) is kept; the two big ones overlap: the better one stays, and it is
    # not dropped for containing the small one (only what lies inside a kept box is).
    assert nms(boxes, scores, 0.3) == [3, 1, 2]
    assert nms(boxes, np.array([3.0, 2.0, 0.5, 1.0]), 0.3) == [0, 2]


def _det(x: float, y: float, w: float, h: float, score: float = 1.0) -> Detection:
    return Detection("person", (x, y, w, h), score)


def test_pick_prefers_the_largest_then_the_most_central() -> None:
    shape = (240, 320, 3)
    near_edge_big = _det(0, 20, 60, 180)
    central_small = _det(140, 60, 40, 100)
    assert pick([central_small, near_edge_big], shape) == near_edge_big  # 180 * 0.59 > 100 * 1.0
    central_alike = _det(130, 20, 60, 140)
    assert pick([near_edge_big, central_alike], shape) == central_alike
    assert pick([], shape) is None


def test_pick_near_the_last_box_prefers_the_same_target_over_a_nearer_stranger() -> None:
    shape = (240, 320, 3)
    last = (20.0, 50.0, 40.0, 100.0)
    same = _det(30, 52, 38, 96)
    stranger = _det(150, 10, 70, 200)  # bigger and central: chosen without `near`
    assert pick([stranger, same], shape) == stranger
    assert pick([stranger, same], shape, near=last) == same


@pytest.mark.parametrize(
    ("field", "value"), [("work_width", 10), ("nms_iou", 1.5), ("scale_step", 1.0), ("min_face_px", 8)]
)
def test_bad_parameters_name_the_field_and_the_range(field: str, value: float) -> None:
    with pytest.raises(CommandRangeError, match=field):
        DetectorParams(**{field: value})  # type: ignore[arg-type]


def test_kinds_and_their_heights() -> None:
    with pytest.raises(CommandRangeError, match="kind"):
        detector_for("cat")
    assert TARGET_HEIGHT_M == {"person": 1.7, "face": 0.16}


def test_an_opencv_without_hog_and_haar_names_what_to_install(monkeypatch: pytest.MonkeyPatch) -> None:
    """OpenCV 5 moved HOG and the cascades to its contrib modules: the error says which OpenCV to get."""
    import types

    from host_sdk.extras import MissingDependencyError

    fake = types.ModuleType("cv2")
    fake.__version__ = "5.0.0"  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, "cv2", fake)
    for kind in ("person", "face"):
        with pytest.raises(
            MissingDependencyError, match=r"OpenCV 5\.0\.0 does not have .*opencv-python-headless>=4\.8,<5"
        ):
            detector_for(kind)


def test_the_installed_opencv_has_the_detectors() -> None:
    """The detectors' tests above skip without them; this one says why, and fails (the vision and dev
    extras ask for an OpenCV that has them)."""
    import cv2

    assert hasattr(cv2, "HOGDescriptor") and hasattr(cv2, "CascadeClassifier"), (
        f"OpenCV {cv2.__version__} has no HOG people detector or Haar cascades: "
        "pip install 'opencv-python-headless>=4.8,<5' (or reinstall the dev extra)"
    )
    assert os.path.isfile(os.path.join(cv2.data.haarcascades, "haarcascade_frontalface_default.xml"))
