"""A follow run's metrics say what they know: on a robot (no ground truth) collisions, what was hit
and the in-view share are unknown (null), not 0, and the run is named by its URL, not as a world."""

from __future__ import annotations

import json

from host_sdk.perception.tracking import TrackState
from roverlink.commands.follow import _summary
from roverlink.follow.metrics import FollowMetrics, MetricsRecorder, TruthSample

TRUTH_ONLY = ("collisions", "collided_with", "run_into", "in_view_fraction")


def _run(metrics: FollowMetrics, truth: TruthSample | None) -> FollowMetrics:
    recorder = MetricsRecorder(metrics, 0.5)
    for i in range(20):
        recorder.observe(0.05 * i, 0.05, state=TrackState.TRACKING, gap_estimate_m=0.6, mode="follow", truth=truth)
    recorder.finish()
    return metrics


def test_without_ground_truth_collisions_are_unknown_not_zero() -> None:
    m = _run(FollowMetrics("roverlink", "picar", url="/dev/ttyACM0"), truth=None)
    out = json.loads(json.dumps(m.to_json()))
    assert out["ground_truth"] is False
    assert {key: out[key] for key in TRUTH_ONLY} == dict.fromkeys(TRUTH_ONLY)
    assert out["url"] == "/dev/ttyACM0" and out["world"] is None
    assert out["tracked_fraction"] == 1.0 and out["follow_error_mean_m"] == 0.1  # the tracker's own figures
    summary = _summary(m)
    assert "collisions unknown" in summary and "(/dev/ttyACM0)" in summary


def test_with_ground_truth_collisions_are_counted() -> None:
    metrics = FollowMetrics("roverlink", "picar", world="random:3")
    metrics.with_truth()
    m = _run(metrics, TruthSample(in_view=True, gap_m=0.5, collisions=("boxes[1]",), distance_m=1.0))
    out = m.to_json()
    assert out["ground_truth"] is True and out["world"] == "random:3" and out["url"] is None
    assert out["collisions"] == 1 and out["collided_with"] == ["boxes[1]"] and out["run_into"] == 0
    assert out["in_view_fraction"] == 1.0
    assert "collisions 1," in _summary(m) and "(random:3)" in _summary(m)


def test_a_run_with_truth_that_hit_nothing_reports_zero() -> None:
    metrics = FollowMetrics("roverlink", "picar", world="empty")
    metrics.with_truth()
    assert metrics.to_json()["collisions"] == 0 and metrics.collided_with == []
