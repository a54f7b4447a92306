"""What a follow run is judged by, gathered every control period.

From the tracker (any robot): time to the first sight of the target, the share of the time after it
that the tracker had the target, each reacquisition (lost -> found again) and the estimated gap.
From the emulator's ground truth (when there is one): collisions, whether the target was really in
the camera's view (inside the field of view, line of sight clear) and the true gap between the
footprint and the target, of which the following error is the difference from the wanted gap.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

from host_sdk.perception.tracking import TrackState


@dataclass(frozen=True, slots=True)
class TruthSample:
    in_view: bool
    gap_m: float
    collisions: tuple[str, ...]
    """What was hit so far (one entry per contact)."""
    distance_m: float
    """Distance driven so far."""
    run_into: int = 0
    """Of those contacts, the ones the robot did not drive into: it stood or moved away."""


@dataclass
class FollowMetrics:
    pilot: str
    profile: str
    world: str | None = None
    """On the emulator: the world the run was in (a scenario file, random:SEED); None on a robot."""
    url: str | None = None
    """On a robot: the board's port or URL; None on the emulator."""
    duration_s: float = 0.0
    distance_m: float = 0.0
    collisions: int | None = None
    """Contacts with obstacles or the target: only the emulator's truth knows them (None: unknown)."""
    collided_with: list[str] | None = None
    run_into: int | None = None
    """Of the collisions, those in which the robot stood or moved away (the target walked into it)."""
    first_sight_s: float | None = None
    """When the tracker first had the target (None: never)."""
    in_view_fraction: float | None = None
    """Truth: share of the time from the first sight that the target was in the camera's view."""
    tracked_fraction: float | None = None
    """Share of the time from the first sight that the tracker reported the target."""
    follow_error_mean_m: float | None = None
    """|gap - wanted gap| while the target was in view (truth when known, else the estimate)."""
    follow_error_max_m: float | None = None
    reacquisitions_s: list[float] = field(default_factory=list)
    """How long each loss of the target lasted until the tracker found it again."""
    mode_s: dict[str, float] = field(default_factory=dict)
    """Time spent in each mode of the pilot."""
    failsafes: int = 0
    decide_ms_mean: float | None = None
    """CPU time the pilot took to decide each control step (the follower and its planner), mean."""
    decide_ms_p99: float | None = None
    follow_gap_m: float = 0.5
    """The gap the following error is measured against."""
    ground_truth: bool = False
    """True on the emulator: collisions, in-view share and gaps come from its truth. False on a
    robot: what only the truth knows (collisions, what was hit, the in-view share) is None."""
    robot_file: str | None = None
    """The robot file the run's robot was described by (`profile` is then its name)."""

    def with_truth(self) -> None:
        """The run has ground truth: its collisions are counted from none."""
        self.ground_truth = True
        self.collisions, self.collided_with, self.run_into = 0, [], 0

    def to_json(self) -> dict[str, Any]:
        out = asdict(self)
        for key, value in out.items():
            if isinstance(value, float):
                out[key] = round(value, 4)
        out["reacquisitions_s"] = [round(v, 3) for v in self.reacquisitions_s]
        out["mode_s"] = {k: round(v, 2) for k, v in self.mode_s.items()}
        return out


class MetricsRecorder:
    def __init__(self, metrics: FollowMetrics, follow_gap_m: float) -> None:
        self.m = metrics
        self.follow_gap_m = follow_gap_m
        self._t0: float | None = None
        self._following_s = 0.0
        self._in_view_s = 0.0
        self._tracked_s = 0.0
        self._errors: list[float] = []
        self._lost_since: float | None = None
        self._found_once = False
        self._decide_s: list[float] = []
        self._decide_total_s = 0.0

    def begin(self, t: float) -> None:
        """The run starts (its duration counts from here)."""
        self._t0 = t

    def observe(
        self,
        t: float,
        dt: float,
        *,
        state: TrackState | None,
        gap_estimate_m: float | None,
        mode: str,
        truth: TruthSample | None,
    ) -> None:
        m = self.m
        if self._t0 is None:
            self._t0 = t
        m.duration_s = t - self._t0
        m.mode_s[mode] = m.mode_s.get(mode, 0.0) + dt
        found = state is not None and state is not TrackState.LOST
        if found and not self._found_once:
            self._found_once = True
            m.first_sight_s = t - self._t0
        if self._found_once:
            if state is TrackState.LOST and self._lost_since is None:
                self._lost_since = t
            elif found and self._lost_since is not None:
                m.reacquisitions_s.append(t - self._lost_since)
                self._lost_since = None
            self._following_s += dt
            self._tracked_s += dt if found else 0.0
            in_view = truth.in_view if truth is not None else found
            self._in_view_s += dt if in_view else 0.0
            gap = truth.gap_m if truth is not None else gap_estimate_m
            if in_view and gap is not None:
                self._errors.append(abs(gap - self.follow_gap_m))
        if truth is not None:
            m.collided_with = list(truth.collisions)
            m.collisions = len(truth.collisions)
            m.run_into = truth.run_into
            m.distance_m = truth.distance_m
        if self._following_s > 0:
            m.tracked_fraction = self._tracked_s / self._following_s
            m.in_view_fraction = self._in_view_s / self._following_s if truth is not None else None
        if self._errors:
            m.follow_error_mean_m = sum(self._errors) / len(self._errors)
            m.follow_error_max_m = max(self._errors)

    def decided(self, seconds: float) -> None:
        """How long the pilot took to decide one control step (CPU time of the loop's thread)."""
        self._decide_s.append(seconds)
        self._decide_total_s += seconds  # a running sum: a run on a robot lasts hours of steps
        self.m.decide_ms_mean = 1000 * self._decide_total_s / len(self._decide_s)

    def finish(self) -> None:
        """The run is over: the figures that need all of it."""
        if self._decide_s:
            ordered = sorted(self._decide_s)
            self.m.decide_ms_p99 = 1000 * ordered[min(len(ordered) - 1, int(0.99 * len(ordered)))]

    def add_distance(self, metres: float) -> None:
        """Distance driven, from odometry (a real robot has no truth to take it from)."""
        if not math.isfinite(metres):
            return
        self.m.distance_m += abs(metres)
