"""The figures benchmarks/tracking.py reports for one tracker on one scene, and the project's goals.

Every figure is over the frames after the first (where each tracker is given its start):

* **accuracy**: among the frames where at least VISIBLE (80 %) of the object is in view, the share
  where the tracker reports it found and its box centre is within NEAR (a quarter) of the object's
  size of the truth's centre; the size is the larger side of the truth box;
* **kept**: frames with IoU >= 0.5 against the truth, as a share of the frames it is in the picture;
* **false found**: frames where the tracker reports the object while it is out of the picture
  (no truth box);
* **reacquire**: seconds, at the scene's frame rate, from the first frame at least BACK (95 %) of the
  object is in view after it was out of the picture, until the first frame that counts as accurate;
  the worst return when there are several; None ("never") when it did not by the end;
* **fps**: frames per second of process CPU time, separately over the frames where the tracker was
  tracking and where it was searching (re-detecting: lost, or finding the object again).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from tests.support.photo_sequences import iou

Box = tuple[float, float, float, float]
VISIBLE = 0.8
NEAR = 0.25
BACK = 0.95
GOALS = {"false_found": 3, "reacquire_s": 1.0, "fps_tracking": 200.0, "fps_searching": 30.0}
"""At most 3 false found, back within 1 s, >= 200 fps tracking and >= 30 fps re-detecting."""


@dataclass(frozen=True)
class Truth:
    box: Box | None
    visible: float


@dataclass(frozen=True)
class Step:
    """What a tracker did on one frame."""

    box: Box | None
    """Where it reports the object; None when it reports it lost."""
    searching: bool
    cpu_s: float


@dataclass(frozen=True)
class Score:
    scene: str
    tracker: str
    accuracy: float | None
    counted: int
    """Frames the accuracy is over (the object at least 80 % in view)."""
    kept: float | None
    false_found: int
    out_of_view: int
    reacquire_s: float | None
    returns: int
    """How often the object came fully back after being out of the picture."""
    fps_tracking: float | None
    tracking_frames: int
    fps_searching: float | None
    searching_frames: int

    def meets(self, figure: str) -> bool | None:
        """Whether `figure` meets its goal; None when there is nothing to judge."""
        if figure == "false_found":
            return self.false_found <= GOALS[figure] if self.out_of_view else None
        if figure == "reacquire_s":
            return None if not self.returns else self.reacquire_s is not None and self.reacquire_s <= GOALS[figure]
        value = getattr(self, figure)
        return None if value is None else bool(value >= GOALS[figure])


def centre(box: Box) -> tuple[float, float]:
    return box[0] + box[2] / 2, box[1] + box[3] / 2


def near(box: Box | None, truth: Box | None) -> bool:
    """The box's centre within a quarter of the truth's larger side of the truth's centre."""
    if box is None or truth is None:
        return False
    (bx, by), (tx, ty) = centre(box), centre(truth)
    return bool(((bx - tx) ** 2 + (by - ty) ** 2) ** 0.5 <= NEAR * max(truth[2], truth[3]))


def reacquire(truth: Sequence[Truth], hits: Sequence[bool], fps: float) -> tuple[float | None, int]:
    """The worst time from a full return to the first accurate frame, and how many returns."""
    worst: float | None = 0.0
    returns = 0
    out = False
    for i in range(1, len(truth)):
        if truth[i].box is None:
            out = True
        elif out and truth[i].visible >= BACK:
            out = False
            returns += 1
            held = next((j for j in range(i, len(truth)) if hits[j]), None)
            worst = None if held is None or worst is None else max(worst, (held - i) / fps)
    return (worst if returns else None), returns


def _rate(steps: Sequence[Step]) -> float | None:
    cpu = sum(s.cpu_s for s in steps)
    return len(steps) / max(cpu, 1e-9) if steps else None


def score(scene: str, tracker: str, truth: Sequence[Truth], steps: Sequence[Step], fps: float) -> Score:
    """`truth` and `steps` are per frame, the first frame (the start) included; its step is ignored."""
    if len(truth) != len(steps):
        raise ValueError(f"steps: {len(steps)} frames, the truth has {len(truth)}")
    frames = range(1, len(truth))
    hits = [i > 0 and steps[i].box is not None and near(steps[i].box, truth[i].box) for i in range(len(truth))]
    counted = [i for i in frames if truth[i].visible >= VISIBLE and truth[i].box is not None]
    in_view = [i for i in frames if truth[i].box is not None]
    out = [i for i in frames if truth[i].box is None]
    reacquire_s, returns = reacquire(truth, hits, fps)
    tracking = [steps[i] for i in frames if not steps[i].searching]
    searching = [steps[i] for i in frames if steps[i].searching]
    return Score(
        scene=scene,
        tracker=tracker,
        accuracy=sum(hits[i] for i in counted) / len(counted) if counted else None,
        counted=len(counted),
        kept=sum(iou(steps[i].box, truth[i].box) >= 0.5 for i in in_view) / len(in_view) if in_view else None,
        false_found=sum(steps[i].box is not None for i in out),
        out_of_view=len(out),
        reacquire_s=reacquire_s,
        returns=returns,
        fps_tracking=_rate(tracking),
        tracking_frames=len(tracking),
        fps_searching=_rate(searching),
        searching_frames=len(searching),
    )
