"""People and faces in camera frames, with detectors that ship inside OpenCV (no weights to download).

    detector = detector_for("face")                      # or "person"
    found = detector.detect(frame.image)                 # boxes with a score, best first
    target = pick(found, frame.image.shape)              # the one to follow (None: nobody)

- **person**: OpenCV's HOG people detector (`HOGDescriptor_getDefaultPeopleDetector`, Dalal and
  Triggs): upright, mostly unoccluded whole bodies at least 64 x 128 pixels (a 48 x 96 window for
  the Daimler variant is not used); the score is the linear SVM's margin.
- **face**: the Haar cascades under `cv2.data.haarcascades`: frontal faces, and (`profile=True`)
  faces turned sideways, either way (the profile cascade knows one side; the mirrored frame gives
  the other). At least `min_face_px` (24) pixels across; the score is the cascade's last-stage
  level weight.

Both run on a copy reduced to `work_width` pixels across (320 by default: a 640 x 480 frame costs
a quarter as much; the smallest person or face found doubles in the full frame) and give boxes in
the frame's own pixels. Overlapping boxes are merged by non-maximum suppression (`nms`), the
highest score kept.

The pick rule (`pick`): with no earlier box, the largest (a person or a face of one size: the
largest is the nearest) weighted down towards the frame's edge, to half at the edge (the most
central of two alike; the robot has to turn less to keep it in view). With the box where the
target was last seen (`near`), the one nearest that box in place and in size: re-detection
prefers the same person over a nearer stranger.

HOG and the Haar cascades are in OpenCV 4 (`opencv-python-headless` 4.x: the `vision` extra);
OpenCV 5 moved both to its contrib modules, so with OpenCV 5 `detector_for` raises
MissingDependencyError naming what to install.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from host_sdk.errors import CommandRangeError
from host_sdk.extras import MissingDependencyError, require

Image = NDArray[np.uint8]
Box = tuple[float, float, float, float]
"""x, y (top-left), width, height in pixels (as the tracker's)."""
Kind = Literal["person", "face"]
KINDS: tuple[Kind, ...] = ("person", "face")
TARGET_HEIGHT_M: dict[Kind, float] = {"person": 1.7, "face": 0.16}
"""The real height of what each detector's box spans (for the range estimate): a standing adult's
HOG box is about their height (1.7 m); the frontal cascade's box spans about two thirds of a
head (forehead to chin, measured on the astronaut photo: 95 of ~145 pixels), about 0.16 m."""


@dataclass(frozen=True, slots=True)
class Detection:
    kind: Kind
    box: Box
    """x, y (top-left), width, height in the frame's pixels."""
    score: float
    """The detector's confidence (HOG: SVM margin; Haar: level weight); higher is surer."""

    @property
    def centre(self) -> tuple[float, float]:
        return box_centre(self.box)


def box_centre(box: Box) -> tuple[float, float]:
    return box[0] + box[2] / 2, box[1] + box[3] / 2


@dataclass(frozen=True, slots=True)
class DetectorParams:
    work_width: int = 320
    """Frames wider than this are reduced to it before detection (pixels)."""
    nms_iou: float = 0.3
    """Boxes overlapping the best by more than this intersection-over-union are dropped."""
    min_score: float | None = None
    """Detections scoring less are dropped (default: the kind's: person 0.9, face 2.0; HOG gave
    0.6-0.75 on a space helmet and a rocket gantry in the test photos)."""
    min_face_px: int = 24
    """Smallest face searched for, pixels across in the reduced frame (the cascades' window)."""
    profile: bool = False
    """Faces: also look for faces turned sideways (three cascade runs in place of one: about a
    third of the frame rate, docs/autonomy.md)."""
    scale_step: float = 1.1
    """Between pyramid levels (both detectors)."""

    def __post_init__(self) -> None:
        if not (isinstance(self.work_width, int) and self.work_width >= 64):
            raise CommandRangeError("work_width", self.work_width, "a whole number of pixels >= 64")
        if not 0.0 < self.nms_iou < 1.0:
            raise CommandRangeError("nms_iou", self.nms_iou, "0..1 (exclusive)")
        if not 1.01 <= self.scale_step <= 2.0:
            raise CommandRangeError("scale_step", self.scale_step, "1.01..2.0")
        if not (isinstance(self.min_face_px, int) and self.min_face_px >= 20):
            raise CommandRangeError("min_face_px", self.min_face_px, "a whole number of pixels >= 20")


DEFAULT_MIN_SCORE: dict[Kind, float] = {"person": 0.9, "face": 2.0}


class Detector(Protocol):
    kind: Kind

    def detect(self, image: Image) -> list[Detection]:
        """Every box found in a BGR `image`, best first, after non-maximum suppression."""
        ...


class DetectorUnavailableError(MissingDependencyError):
    """OpenCV is installed but without what a detector needs."""

    def __init__(self, what: str, detail: str) -> None:
        super().__init__("cv2", "vision", what)
        self.msg = f"{what} needs {detail}"  # what ImportError's str() shows
        self.args = (self.msg,)


def _cv2(what: str) -> Any:
    cv2 = require("cv2", "vision", what)
    if not (hasattr(cv2, "HOGDescriptor") and hasattr(cv2, "CascadeClassifier")):
        raise DetectorUnavailableError(
            what,
            f"OpenCV's HOG and Haar cascade detectors, which OpenCV {cv2.__version__} does not have (OpenCV 5 "
            "moved them to its contrib modules): pip install 'opencv-python-headless>=4.8,<5'",
        )
    return cv2


def _reduced(cv2: Any, image: Image, work_width: int) -> tuple[Image, float]:
    """The frame reduced to `work_width` across (as is if narrower) and the factor back to it."""
    if not (isinstance(image, np.ndarray) and image.ndim == 3 and image.shape[2] == 3):
        raise CommandRangeError("image", getattr(image, "shape", image), "a BGR image (H x W x 3)")
    w = image.shape[1]
    if w <= work_width:
        return image, 1.0
    f = work_width / w
    return cv2.resize(image, None, fx=f, fy=f, interpolation=cv2.INTER_AREA), 1 / f


def _finish(
    kind: Kind, boxes: NDArray[np.float64], scores: NDArray[np.float64], back: float, params: DetectorParams
) -> list[Detection]:
    least = DEFAULT_MIN_SCORE[kind] if params.min_score is None else params.min_score
    keep = [i for i in nms(boxes, scores, params.nms_iou) if scores[i] >= least]
    return [Detection(kind, tuple(float(v) * back for v in boxes[i]), float(scores[i])) for i in keep]  # type: ignore[arg-type]


class PersonDetector:
    """Upright whole bodies: OpenCV's HOG + linear SVM people detector."""

    kind: Kind = "person"

    def __init__(self, params: DetectorParams | None = None) -> None:
        self.params = params or DetectorParams()
        self.cv2 = _cv2("the person detector")
        self.hog = self.cv2.HOGDescriptor()
        self.hog.setSVMDetector(self.cv2.HOGDescriptor_getDefaultPeopleDetector())

    def detect(self, image: Image) -> list[Detection]:
        small, back = _reduced(self.cv2, image, self.params.work_width)
        # groupThreshold=0: every window, grouped by our own NMS (which keeps the scores).
        found, weights = self.hog.detectMultiScale(
            small, winStride=(8, 8), padding=(8, 8), scale=self.params.scale_step, groupThreshold=0
        )
        boxes = np.asarray(found, dtype=np.float64).reshape(-1, 4)
        return _finish("person", boxes, np.asarray(weights, dtype=np.float64).ravel(), back, self.params)


class FaceDetector:
    """Faces: the frontal Haar cascade and, with `profile`, the profile one on the frame and its mirror."""

    kind: Kind = "face"

    def __init__(self, params: DetectorParams | None = None) -> None:
        self.params = params or DetectorParams()
        self.cv2 = _cv2("the face detector")
        self.frontal = self._cascade("haarcascade_frontalface_default.xml")
        self.side = self._cascade("haarcascade_profileface.xml") if self.params.profile else None

    def _cascade(self, name: str) -> Any:
        path = os.path.join(self.cv2.data.haarcascades, name)
        cascade = self.cv2.CascadeClassifier(path)
        if cascade.empty():
            raise DetectorUnavailableError("the face detector", f"{path}, which OpenCV could not load")
        return cascade

    def _run(self, cascade: Any, gray: Image) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        m = self.params.min_face_px
        found, _, weights = cascade.detectMultiScale3(
            gray, scaleFactor=self.params.scale_step, minNeighbors=4, minSize=(m, m), outputRejectLevels=True
        )
        return np.asarray(found, dtype=np.float64).reshape(-1, 4), np.asarray(weights, dtype=np.float64).ravel()

    def detect(self, image: Image) -> list[Detection]:
        small, back = _reduced(self.cv2, image, self.params.work_width)
        gray = self.cv2.equalizeHist(self.cv2.cvtColor(small, self.cv2.COLOR_BGR2GRAY))
        parts = [self._run(self.frontal, gray)]
        if self.side is not None:
            parts.append(self._run(self.side, gray))
            mirrored, weights = self._run(self.side, gray[:, ::-1].copy())
            if mirrored.shape[0]:
                mirrored[:, 0] = gray.shape[1] - mirrored[:, 0] - mirrored[:, 2]
            parts.append((mirrored, weights))
        boxes = np.concatenate([b for b, _ in parts])
        return _finish("face", boxes, np.concatenate([s for _, s in parts]), back, self.params)


def detector_for(kind: str, params: DetectorParams | None = None) -> Detector:
    """The detector for `kind` ("person" or "face")."""
    if kind == "person":
        return PersonDetector(params)
    if kind == "face":
        return FaceDetector(params)
    raise CommandRangeError("kind", kind, " or ".join(KINDS))


def iou(a: Box, b: Box) -> float:
    """Intersection over union of two boxes (x, y, w, h)."""
    ix = max(0.0, min(a[0] + a[2], b[0] + b[2]) - max(a[0], b[0]))
    iy = max(0.0, min(a[1] + a[3], b[1] + b[3]) - max(a[1], b[1]))
    inter = ix * iy
    union = a[2] * a[3] + b[2] * b[3] - inter
    return inter / union if union > 0 else 0.0


def nms(boxes: NDArray[np.float64], scores: NDArray[np.float64], max_iou: float) -> list[int]:
    """Greedy non-maximum suppression: indices kept, highest score first; a box overlapping a kept
    one by more than `max_iou` (intersection over union), or lying inside it, is dropped."""
    kept: list[int] = []
    for i in np.argsort(-scores, kind="stable"):
        box = tuple(boxes[i])
        if all(iou(box, tuple(boxes[k])) <= max_iou and not _inside(box, tuple(boxes[k])) for k in kept):
            kept.append(int(i))
    return kept


def _inside(a: Box, b: Box) -> bool:
    """Most of `a` lies within `b` (a window on part of a body already found)."""
    ix = max(0.0, min(a[0] + a[2], b[0] + b[2]) - max(a[0], b[0]))
    iy = max(0.0, min(a[1] + a[3], b[1] + b[3]) - max(a[1], b[1]))
    return ix * iy > 0.8 * a[2] * a[3]


def pick(found: Sequence[Detection], shape: Sequence[int], near: Box | None = None) -> Detection | None:
    """The detection to follow in a frame of `shape` (H, W, ...), None if there is none.

    Without `near`: the largest (the nearest, for people or faces of one size), its height weighted
    down linearly to half at the frame's side edges (of two alike, the more central). With `near`
    (where the target was last seen): the one most like it in place and size, i.e. the highest of
    1 / (1 + distance between centres / its height) * smaller height / larger height."""
    if not found:
        return None
    H, W = shape[0], shape[1]

    def value(d: Detection) -> float:
        cx, cy = d.centre
        h = d.box[3]
        if near is None:
            off = min(1.0, abs(cx - W / 2) / (W / 2))
            return h / H * (1.0 - 0.5 * off)
        nx, ny = box_centre(near)
        dist = math.hypot(cx - nx, cy - ny)
        return 1.0 / (1.0 + dist / max(near[3], 1.0)) * min(h, near[3]) / max(h, near[3], 1e-9)

    return max(found, key=value)
