"""`roverlink follow`'s run: the SDK's control loop (host_sdk.autonomy.ControlLoop) for a set time,
with the metrics taken every period (and judged by the emulator's truth when there is one). The loop
rides through the robot's failures (host_sdk.supervisor): after a failsafe or a board reset the
robot stays disarmed unless `rearm` (an opt-in) lets the loop arm it again."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from host_sdk.autonomy import ControlLoop, Pilot
from host_sdk.perception.tracking import TrackState
from host_sdk.robot import Robot
from host_sdk.sensors import CameraSource, Jy901, Lidar
from host_sdk.supervisor import Supervisor
from roverlink.follow.metrics import FollowMetrics, MetricsRecorder, TruthSample


@dataclass(frozen=True, slots=True)
class Progress:
    t_s: float
    mode: str
    tracked: bool
    gap_m: float | None
    metrics: FollowMetrics
    failsafe: str | None = None
    """A failsafe met since the last line, in words (ControlLoop.last_failsafe)."""
    trouble: str | None = None
    """What is wrong with the robot now and what to do (the supervisor's banner), None: nothing."""


def run_follow(
    robot: Robot | Supervisor,
    lidar: Lidar,
    camera: CameraSource,
    pilot: Pilot,
    *,
    duration_s: float,
    metrics: FollowMetrics,
    follow_gap_m: float = 0.5,
    imu: Jy901 | None = None,
    truth: Callable[[], TruthSample] | None = None,
    period_s: float = 0.05,
    progress: Callable[[Progress], None] | None = None,
    progress_every_s: float = 1.0,
    on_step: Callable[[float], None] | None = None,
    rearm: bool = False,
) -> FollowMetrics:
    """Run `pilot` for `duration_s` of the robot's clock (armed at the start; again after a failsafe or
    a reset only with `rearm`); returns the filled `metrics`."""
    recorder = MetricsRecorder(metrics, follow_gap_m)
    if truth is not None:
        metrics.with_truth()
    metrics.follow_gap_m = follow_gap_m
    loop = ControlLoop(robot, pilot, lidar=lidar, camera=camera, imu=imu, period_s=period_s, arm=True, rearm=rearm)
    t0 = loop.start()
    recorder.begin(t0.time_s)
    next_progress = last_t = t0.time_s
    told = 0
    try:
        while loop.supervisor.now() - t0.time_s < duration_s:
            step = loop.step()
            t = step.pose.time_s
            recorder.decided(step.decide_s)
            metrics.failsafes = loop.failsafes
            decision = getattr(pilot, "decision", None)
            gap = getattr(decision, "gap_m", None)
            sample = truth() if truth is not None else None
            recorder.observe(t, t - last_t, state=step.track, gap_estimate_m=gap, mode=step.mode, truth=sample)
            if sample is None:
                metrics.distance_m = loop.poses.distance_m
            last_t = t
            if on_step is not None:
                on_step(t)
            if progress is not None and t >= next_progress:
                next_progress += progress_every_s
                tracked = step.track is not None and step.track is not TrackState.LOST
                news = loop.last_failsafe if loop.failsafes > told else None
                told = loop.failsafes
                banner = step.health.banner()
                trouble = None if banner is None else f"{banner.text}; {banner.hint}"
                progress(Progress(t - t0.time_s, step.mode, tracked, gap, metrics, news, trouble))
            loop.wait()
    finally:
        metrics.duration_s = loop.supervisor.now() - t0.time_s
        recorder.finish()
        loop.stop()
    return metrics
