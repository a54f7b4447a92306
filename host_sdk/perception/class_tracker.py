"""Follow a person or a face: a detector picks one, the template `Tracker` follows it, and when the
tracker has lost it for a while the detector looks for one again.

    tracker = ClassTracker("person", camera)              # or "face"; height_m: the range estimate's
    track = tracker.update(frame.image, frame.time_s)     # a Track, as Tracker.update gives

Policy (every frame; the detector's cost is bounded by `detect_every_s`):

1. No target yet: the detector runs (at most every `detect_every_s`) and `pick` chooses the largest,
   most central one; a `Tracker` starts on its box (`Tracker.from_region`) and the track is
   REACQUIRED.
2. Tracking: the tracker alone, every frame (template matching: a millisecond or so, where the
   detectors take tens, docs/autonomy.md).
3. Lost: the tracker's own re-detection (the template over the whole frame) runs every frame; lost
   for `redetect_after_s`, the detector runs too, and `pick` prefers the box nearest the last one
   seen in place and size (the same person over a nearer stranger); a new tracker starts on it.

The range estimate assumes the kind's real height (`TARGET_HEIGHT_M`: 1.7 m for a person's box,
0.16 m for a face's) unless `height_m` is given.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Protocol

from host_sdk.body import CameraModel
from host_sdk.errors import CommandRangeError
from host_sdk.perception.detectors import (
    KINDS,
    TARGET_HEIGHT_M,
    Box,
    Detection,
    Detector,
    Image,
    detector_for,
    pick,
)
from host_sdk.perception.tracker_params import TrackerParams
from host_sdk.perception.tracking import Track, Tracker, TrackState


class FrameTracker(Protocol):
    """What a pilot feeds frames to: a `Tracker` or a `ClassTracker`."""

    def update(self, image: Image, time_s: float, *, rotation_rad: float = 0.0) -> Track: ...

    def detect(self, image: Image, time_s: float) -> Track: ...


@dataclass(frozen=True, slots=True)
class ClassTrackerParams:
    redetect_after_s: float = 0.5
    """Lost this long, the detector looks for the class again (before that, only the tracker's own
    re-detection: a target hidden for a moment comes back without it)."""
    detect_every_s: float = 0.2
    """The detector runs at most this often while looking (5 Hz: tens of ms each)."""

    def __post_init__(self) -> None:
        for name in ("redetect_after_s", "detect_every_s"):
            value = getattr(self, name)
            if not 0.0 <= value <= 60.0:
                raise CommandRangeError(name, value, "0..60 s")


class ClassTracker:
    def __init__(
        self,
        kind: str,
        camera: CameraModel,
        *,
        height_m: float | None = None,
        params: ClassTrackerParams | None = None,
        tracker_params: TrackerParams | None = None,
        detector: Detector | None = None,
    ) -> None:
        if kind not in KINDS:
            raise CommandRangeError("kind", kind, " or ".join(KINDS))
        if height_m is not None and not 0.0 < height_m < 10.0:
            raise CommandRangeError("height_m", height_m, "0..10 m (exclusive)")
        self.kind = kind
        self.camera = camera
        self.height_m = TARGET_HEIGHT_M[kind] if height_m is None else height_m
        self.params = params or ClassTrackerParams()
        self.tracker_params = tracker_params
        self.detector = detector or detector_for(kind)
        self.tracker: Tracker | None = None
        self.last_box: Box | None = None
        """Where the target was last seen (what re-detection prefers)."""
        self.detections: list[Detection] = []
        """What the detector found the last time it ran (for live views)."""
        self.detector_runs = 0
        self.acquisitions = 0
        """How often the detector (re)started the tracker."""
        self._lost_since: float | None = None
        self._detected_at: float | None = None

    def update(self, image: Image, time_s: float, *, rotation_rad: float = 0.0) -> Track:
        """This frame's track (the same contract as `Tracker.update`)."""
        p = self.params
        if self.tracker is not None:
            track = self.tracker.update(image, time_s, rotation_rad=rotation_rad)
            if track.found:
                self.last_box, self._lost_since = track.box, None
                return track
        if self._lost_since is None:
            self._lost_since = time_s
        waited = self.tracker is None or time_s - self._lost_since >= p.redetect_after_s
        due = self._detected_at is None or time_s - self._detected_at >= p.detect_every_s
        if waited and due:
            return self.detect(image, time_s)
        return self._lost(time_s)

    def detect(self, image: Image, time_s: float) -> Track:
        """Run the detector now: REACQUIRED on the box picked (a new tracker follows it), or LOST."""
        self._detected_at = time_s
        self.detector_runs += 1
        self.detections = self.detector.detect(image)
        chosen = pick(self.detections, image.shape, near=self.last_box)
        box = None if chosen is None else _clipped(chosen.box, image.shape[1], image.shape[0])
        if box is None:
            if self._lost_since is None:
                self._lost_since = time_s
            return self._lost(time_s)
        self.tracker = Tracker.from_region(
            image, box, self.camera, height_m=self.height_m, params=self.tracker_params, time_s=time_s
        )
        self.acquisitions += 1
        self.last_box, self._lost_since = box, None
        # The template is the frame's own pixels: matching it there places the box and gives the
        # track its bearing and range exactly as the tracker reports them from now on.
        track = self.tracker.update(image, time_s)
        return replace(track, state=TrackState.REACQUIRED) if track.found else track

    def _lost(self, time_s: float) -> Track:
        since = self._lost_since if self._lost_since is not None else time_s
        return Track(TrackState.LOST, time_s, None, 0.0, None, None, time_s - since)


def _clipped(box: Box, width: int, height: int) -> Box | None:
    """The box cut to the frame (HOG's windows reach past its edge); None if little is left."""
    x0, y0 = round(max(0.0, box[0])), round(max(0.0, box[1]))
    x1, y1 = min(width, round(box[0] + box[2])), min(height, round(box[1] + box[3]))
    if x1 - x0 < 8 or y1 - y0 < 8:
        return None
    return x0, y0, x1 - x0, y1 - y0
