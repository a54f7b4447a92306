"""The follow loop: sensors in, a pilot's twist out, every control period, for a set time.

Per period (`period_s`, 20 Hz by default): complete lidar revolutions, the newest camera frame and
the IMU's samples are read without waiting; each goes to the pilot with the robot's pose at the time
it was taken (from a short history of poses); the pilot's twist is sent (every period: setpoints are
cheap, and renewing them keeps the board's watchdog fed); the metrics take their sample. The pose is
the EKF's (wheel odometry + gyro) when an IMU is given, else wheel odometry.

Waiting is `robot.sleep()`, so the same loop runs on a real robot (wall clock) and on the emulator's
virtual clock (as fast as the CPU allows, deterministic).
"""

from __future__ import annotations

import bisect
import math
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

from host_sdk import FeedbackSample, NotArmedError, Robot, RoverLinkError
from host_sdk.fusion import OdometryIncrements, PoseEkf
from host_sdk.perception.tracking import TrackState
from host_sdk.sensors import CameraFrame, CameraSource, Jy901, Lidar
from roverlink.follow.metrics import FollowMetrics, MetricsRecorder, TruthSample
from roverlink.follow.pilots import Pilot, Pose2D


@dataclass(frozen=True, slots=True)
class Progress:
    t_s: float
    mode: str
    tracked: bool
    gap_m: float | None
    metrics: FollowMetrics


class FrameGrabber:
    """The newest camera frame without waiting. A byte-stream source queues its frames (the emulator's
    in-process camera): take the newest. An OpenCV capture blocks in `read()` until the next frame,
    up to a frame period, or longer when the camera stalls: read it on a thread of its own."""

    def __init__(self, camera: CameraSource) -> None:
        self.camera = camera
        self._frame: CameraFrame | None = None
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        if not camera.queued:
            self._thread = threading.Thread(target=self._run, name="camera", daemon=True)
            self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                frame = self.camera.read(1.0)
            except RoverLinkError:
                continue
            with self._lock:
                self._frame = frame

    def latest(self) -> CameraFrame | None:
        if self._thread is None:
            return self.camera.latest()
        with self._lock:
            frame, self._frame = self._frame, None
        return frame

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)


class PoseSource:
    """The robot's pose now and at recent times: the EKF's with an IMU, else the wheels'."""

    def __init__(self, robot: Robot, imu: Jy901 | None) -> None:
        self.robot = robot
        self.imu = imu
        self.ekf: PoseEkf | None = None
        self._history: deque[tuple[float, Pose2D]] = deque(maxlen=64)
        self.distance_m = 0.0
        self._steps = OdometryIncrements()
        self._odometry: deque[tuple[float, float, float]] = deque()
        """(time, distance, turn) steps from FEEDBACK, not yet fused."""
        if imu is not None:
            self.ekf = PoseEkf(time_s=robot.now())
            robot.on_feedback(self._on_feedback)

    def _on_feedback(self, sample: FeedbackSample) -> None:
        # On the I/O thread: queued, and fused on the loop's thread once the IMU has been read up to
        # now (a step fused before its gyro samples are in would have to guess the turn).
        if sample.pose is not None:
            ds, turn = self._steps.step(sample.pose.x_m, sample.pose.y_m, sample.pose.theta_rad)
            self._odometry.append((sample.host_time_s, ds, turn))

    def update(self, t: float) -> Pose2D:
        if self.imu is not None and self.ekf is not None:
            for sample in self.imu.poll():
                if sample.gyro is not None:
                    self.ekf.add_gyro(sample.t, sample.gyro[2])
            while self._odometry:
                time_s, ds, turn = self._odometry.popleft()
                self.ekf.add_odometry(time_s, ds, turn)
                self.distance_m += abs(ds)
            p = self.ekf.pose
            pose = (p.x_m, p.y_m, p.theta_rad)
        else:
            o = self.robot.odometry.pose
            if self._history:
                last = self._history[-1][1]
                self.distance_m += math.hypot(o.x_m - last[0], o.y_m - last[1])
            pose = (o.x_m, o.y_m, o.theta_rad)
        self._history.append((t, pose))
        return pose

    def at(self, t: float) -> Pose2D:
        """The pose at `t`, interpolated between the recent ones (held beyond them). A control step
        is 50 ms: the nearest pose alone would be up to 2.5 cm and 2 degrees off while turning, which
        is what a lidar revolution is registered and compared by."""
        times = [h[0] for h in self._history]
        i = bisect.bisect_left(times, t)
        if i <= 0:
            return self._history[0][1]
        if i >= len(times):
            return self._history[-1][1]
        (t0, a), (t1, b) = self._history[i - 1], self._history[i]
        f = (t - t0) / (t1 - t0) if t1 > t0 else 1.0
        turn = math.remainder(b[2] - a[2], 2 * math.pi)
        return a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * turn


def run_follow(robot: Robot, lidar: Lidar, camera: CameraSource, pilot: Pilot, *, duration_s: float,
               metrics: FollowMetrics, follow_gap_m: float = 0.5, imu: Jy901 | None = None,
               truth: Callable[[], TruthSample] | None = None, period_s: float = 0.05,
               progress: Callable[[Progress], None] | None = None, progress_every_s: float = 1.0,
               on_step: Callable[[float], None] | None = None) -> FollowMetrics:  # fmt: skip
    """Run `pilot` for `duration_s` of the robot's clock; returns the filled `metrics`."""
    recorder = MetricsRecorder(metrics, follow_gap_m)
    metrics.ground_truth = truth is not None
    metrics.follow_gap_m = follow_gap_m
    poses = PoseSource(robot, imu)
    if not robot.armed:
        robot.arm()
    lidar.start()
    t0 = robot.now()
    recorder.begin(t0)
    pose = poses.update(t0)
    state: TrackState | None = None
    frames = FrameGrabber(camera)
    next_progress = t0
    tick = t0
    last_t = t0
    try:
        while (t := robot.now()) - t0 < duration_s:
            pose = poses.update(t)
            for scan in lidar.poll():
                pilot.on_scan(scan, poses.at(scan.time_s + scan.duration_s / 2), pose_at=poses.at)
            frame = frames.latest()
            if frame is not None:
                track = pilot.on_frame(frame, poses.at(frame.time_s))
                if track is not None:
                    state = track.state
            started = time.thread_time()
            linear, angular, mode = pilot.command(t, pose)
            recorder.decided(time.thread_time() - started)
            try:
                robot.drive(linear, angular, clamp=True)
            except NotArmedError:  # a failsafe (e.g. pushing against something): count it, re-arm
                metrics.failsafes += 1
                robot.arm()
            decision = getattr(pilot, "decision", None)
            gap = getattr(decision, "gap_m", None)
            sample = truth() if truth is not None else None
            recorder.observe(t, t - last_t, state=state, gap_estimate_m=gap, mode=mode, truth=sample)
            if sample is None:
                metrics.distance_m = poses.distance_m
            last_t = t
            if on_step is not None:
                on_step(t)
            if progress is not None and t >= next_progress:
                next_progress += progress_every_s
                tracked = state is not None and state is not TrackState.LOST
                progress(Progress(t - t0, mode, tracked, gap, metrics))
            tick += period_s
            robot.sleep(max(0.0, tick - robot.now()))
    finally:
        frames.close()
    metrics.duration_s = robot.now() - t0
    recorder.finish()
    robot.stop()
    lidar.stop()
    return metrics
