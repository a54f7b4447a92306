"""Object tracking on sequences built from real photographs: RoverLink's Tracker against OpenCV's
trackers, in one run.

    python benchmarks/tracking_photos.py            # about a minute
    python benchmarks/tracking_photos.py --json     # the figures as JSON
    python benchmarks/tracking_photos.py --sequence slide --sequence easy

The sequences (tests/support/photo_sequences.py, seeded): a target cut out of a real photo with a
soft elliptical edge, so its box holds background, moving over another real, cluttered photo
(tests/data/photos, public domain / CC0), 320x240, every frame JPEG at quality 60:

* **slide**: a cat's face slides over a still photo (an astronaut's portrait), nothing else changes
  (90 frames);
* **easy** (the cat's face over a launch pad at dusk), **medium** (the cat's face over a cup on a
  wooden table), **hard** (a red cup and saucer, few corners, over the astronaut's orange suit),
  150 frames each: camera pan, nearing and receding, a few degrees of rotation, exposure swings and
  a step, a pole passing in front, and a stretch of 20-32 frames where the target is out of the
  picture before it comes back; more of each from easy to hard.

Every tracker starts from the true box of frame 0 (what a user would drag round the object) and
runs over the same frames with OpenCV held to one thread. Per sequence and tracker:

* **kept**: frames with IoU >= 0.5 against the truth, as a share of the frames where the target is
  in view (frame 0 excluded);
* **false found**: frames where the tracker reports the target while it is out of view;
* **reacquire**: frames from the target's return until the tracker holds it again (IoU >= 0.5);
  "never" if it did not by the end;
* **fps**: frames per second of process CPU time (best of `--repeat`).

OpenCV's generator is seeded before each OpenCV tracker's run: MIL samples its training patches at
random, and its figures change with the seed (`--mil-seed`). OpenCV's TrackerMIL always comes with
opencv-python-headless; KCF and CSRT need opencv-contrib and
are measured when `cv2.TrackerKCF_create` / `cv2.TrackerCSRT_create` exist.
"""

from __future__ import annotations

import argparse
import gc
import json
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import cv2

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from host_sdk.perception.camera import CameraModel
from host_sdk.perception.tracking import Tracker
from tests.support.photo_sequences import SPECS, Box, iou, sequences
from tests.support.photo_sequences import Sequence as PhotoSequence

CAMERA = CameraModel.pi_camera_v2(320, 240)
Run = Callable[[PhotoSequence], list[Box | None]]


def roverlink(seq: PhotoSequence) -> list[Box | None]:
    first = seq.frames[0]
    assert first.box is not None
    tracker = Tracker.from_region(first.image, first.box, CAMERA)
    return [None, *(tracker.update(f.image, f.time_s).box for f in seq.frames[1:])]


def opencv(make: Callable[[], object], seed: int = 1) -> Run:
    def run(seq: PhotoSequence) -> list[Box | None]:
        cv2.setRNGSeed(seed)  # MIL samples its training patches with OpenCV's global generator
        tracker = make()
        first = seq.frames[0]
        assert first.box is not None
        tracker.init(first.image, tuple(round(v) for v in first.box))  # type: ignore[attr-defined]
        out: list[Box | None] = [None]
        for f in seq.frames[1:]:
            ok, box = tracker.update(f.image)  # type: ignore[attr-defined]
            x, y, w, h = (float(v) for v in box)
            out.append((x, y, w, h) if ok else None)
        return out

    return run


def trackers(mil_seed: int) -> tuple[list[tuple[str, Run]], list[str]]:
    runs: list[tuple[str, Run]] = [
        ("RoverLink Tracker", roverlink),
        ("OpenCV TrackerMIL", opencv(cv2.TrackerMIL_create, mil_seed)),  # type: ignore[attr-defined]
    ]
    missing = []
    for name in ("KCF", "CSRT"):
        make = getattr(cv2, f"Tracker{name}_create", None)
        if make is None:
            missing.append(f"Tracker{name}")
        else:
            runs.append((f"OpenCV Tracker{name}", opencv(make, mil_seed)))
    return runs, missing


@dataclass
class Score:
    sequence: str
    tracker: str
    kept: float
    in_view: int
    false_found: int
    out_of_view: int
    reacquire_frames: int | None
    fps: float


def score(seq: PhotoSequence, name: str, boxes: Sequence[Box | None], fps: float) -> Score:
    truth = [f.box for f in seq.frames]
    view = [i for i in range(1, len(truth)) if truth[i] is not None]
    kept = sum(iou(boxes[i], truth[i]) >= 0.5 for i in view)
    out = [i for i in range(1, len(truth)) if truth[i] is None]
    false_found = sum(boxes[i] is not None for i in out)
    reacquire = None
    if out:
        back = max(out) + 1
        held = [i for i in range(back, len(truth)) if iou(boxes[i], truth[i]) >= 0.5]
        reacquire = held[0] - back if held else None
    return Score(seq.name, name, kept / max(1, len(view)), len(view), false_found, len(out), reacquire, fps)


def timed(run: Run, seq: PhotoSequence, repeat: int) -> tuple[list[Box | None], float]:
    best, boxes = 0.0, []
    for _ in range(repeat):
        gc.collect()
        gc.disable()
        t0 = time.process_time()
        try:
            boxes = run(seq)
        finally:
            elapsed = time.process_time() - t0
            gc.enable()
        best = max(best, (len(seq.frames) - 1) / max(elapsed, 1e-9))
    return boxes, best


def measure(names: tuple[str, ...] | None, repeat: int, mil_seed: int) -> tuple[list[Score], list[str]]:
    runs, missing = trackers(mil_seed)
    scores = []
    for seq in sequences(names):
        for name, run in runs:
            boxes, fps = timed(run, seq, repeat)
            scores.append(score(seq, name, boxes, fps))
    return scores, missing


def report(scores: Sequence[Score], missing: Sequence[str], repeat: int) -> None:
    print(f"320x240 real-photo sequences, JPEG q60, one OpenCV thread, CPU time, best of {repeat}\n")
    print(f"{'sequence':9s} {'tracker':20s} {'kept':>6s} {'false found':>12s} {'reacquire':>10s} {'fps':>7s}")
    for s in scores:
        ff = f"{s.false_found}/{s.out_of_view}" if s.out_of_view else "-"
        re = "-" if not s.out_of_view else ("never" if s.reacquire_frames is None else f"{s.reacquire_frames} fr")
        print(f"{s.sequence:9s} {s.tracker:20s} {100 * s.kept:5.0f}% {ff:>12s} {re:>10s} {s.fps:7.0f}")
    if missing:
        print(f"\nnot available in this OpenCV build (they need opencv-contrib): {', '.join(missing)}")


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=(__doc__ or "").split("\n")[0])
    ap.add_argument("--sequence", action="append", choices=[s.name for s in SPECS], help="default: all")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--json", action="store_true", help="print the figures as JSON")
    ap.add_argument("--mil-seed", type=int, default=1, help="OpenCV's random seed for its trackers (default 1)")
    args = ap.parse_args(argv)
    cv2.setNumThreads(1)
    scores, missing = measure(tuple(args.sequence) if args.sequence else None, args.repeat, args.mil_seed)
    if args.json:
        print(json.dumps({"results": [asdict(s) for s in scores], "not_available": missing}, indent=2))
    else:
        report(scores, missing, args.repeat)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
