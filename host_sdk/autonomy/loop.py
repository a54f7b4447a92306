"""A robot program's control loop: sensors in, a pilot's twist out, every control period.

    loop = ControlLoop(sup, pilot, lidar=lidar, camera=camera, imu=imu, arm=True)   # imu: optional
    with loop:                                  # arms (arm=True), starts the lidar; stops the robot at the end
        while loop.robot.now() - loop.started_s < 60:
            step = loop.step()                  # one period's work; step.mode, step.health say what it does
            loop.wait()                         # until the next period

Per period (`period_s`, 20 Hz by default): complete lidar revolutions, the newest camera frame and
the IMU's samples are read without waiting; each goes to the pilot with the robot's pose at the time
it was taken (`PoseSource`: the EKF's with an IMU, else wheel odometry); the pilot's twist is sent
every period while the robot is armed (setpoints are cheap, and renewing them keeps the board's
watchdog fed).

It rides through the robot's failures (host_sdk.supervisor): a failsafe, a board reset, a lost
link or port, a sensor that stops are state (`step.health`, `sensor_errors`), never an exception
that ends the program. Each time the robot stops being armed and reachable the pilot is told
(`halt(why)`, if it has one: a console's pilot stops following) and the drive command is cleared,
so arming again never drives off. While the link is down the loop commands zero speed: a board that
still hears it stands, one that does not fails safe by its watchdog (and says so when it answers
again), and a short gap in FEEDBACK on a busy host costs no failsafe. Arming is the program's:
`arm=True` arms at the start; re-arming after a failsafe or a reset is an opt-in (`rearm=True`,
logged at the start). A failsafe met while driving is counted and put in words (`last_failsafe`:
with a pilot that has `explain_failsafe`, such as `FollowPilot`, naming what the lidar sees touching
the footprint).

Waiting is `robot.sleep()`, so the same loop runs on a real robot (wall clock) and on the emulator's
virtual clock (as fast as the CPU allows, deterministic).
"""

from __future__ import annotations

import contextlib
import logging
import time
from dataclasses import dataclass

from host_sdk.autonomy.pilot import Halting, Pilot
from host_sdk.errors import RoverLinkError
from host_sdk.failsafe import describe_failsafe
from host_sdk.fusion.source import PoseSource
from host_sdk.perception.tracking import TrackState
from host_sdk.pose import Pose
from host_sdk.robot import Robot
from host_sdk.sensors import CameraFrame, CameraSource, FrameGrabber, Jy901, Lidar, LidarScan
from host_sdk.supervisor import Health, Supervisor
from host_sdk.supervisor.health import LINK_CLOSED, LINK_LOST, LINK_RECONNECTING, LINK_UP

log = logging.getLogger("host_sdk.autonomy")
REARM_RETRY_S = 1.0
"""After a re-arm that failed, the next try waits this long (the refusal is in the health)."""


@dataclass(frozen=True, slots=True)
class Step:
    """What one period did."""

    pose: Pose
    linear_m_s: float
    angular_rad_s: float
    mode: str
    """What the pilot is doing (its own word: "follow", "search", ...)."""
    track: TrackState | None
    """The tracker's state at the newest frame so far (None before the first)."""
    decide_s: float
    """CPU time the pilot took to decide."""
    health: Health
    """The robot's link, arming, failsafe and last reset (what a program shows)."""
    driven: bool
    """The twist was sent (the robot is armed and reachable)."""


class ControlLoop:
    def __init__(
        self,
        robot: Robot | Supervisor,
        pilot: Pilot,
        *,
        lidar: Lidar,
        camera: CameraSource,
        imu: Jy901 | None = None,
        period_s: float = 0.05,
        arm: bool = False,
        rearm: bool = False,
    ) -> None:
        self.supervisor = robot if isinstance(robot, Supervisor) else Supervisor(robot)
        """Owns the robot's lifetime: a `Supervisor.connect(...)` one also opens a lost port again."""
        self.arm_at_start = arm or rearm
        """Arm at the start (the program's own decision to drive)."""
        self.rearm = rearm
        """Arm again after a failsafe or a board reset (an opt-in: a robot disarmed by a failsafe stays
        so until the user arms it, by default)."""
        self.pilot = pilot
        self.lidar = lidar
        self.camera = camera
        self.period_s = period_s
        self.poses = PoseSource(self.supervisor.robot, imu)
        self.failsafes = 0
        """Times the robot stopped being armed and reachable while driving (failsafes, resets, lost links)."""
        self.last_failsafe: str | None = None
        """The last failsafe met while driving, in words (what it means, and what the lidar saw at the footprint)."""
        self.sensor_errors: dict[str, str] = {}
        """Why a sensor stopped being read ("lidar", "camera"): the loop goes on without it."""
        self.started_s = 0.0
        self._frames: FrameGrabber | None = None
        self._track: TrackState | None = None
        self._tick = 0.0
        self._halts = 0
        self._driving = False
        self._pose: Pose | None = None
        self._rearm_at = 0.0

    @property
    def robot(self) -> Robot:
        """The robot now (another object once a lost port was opened again)."""
        return self.supervisor.robot

    def start(self) -> Pose:
        """Arm (with `arm` or `rearm`), start the lidar and the camera reader; the pose at the start."""
        if self.rearm:
            log.warning(
                "%s: rearm is on: the control loop arms again by itself after a failsafe or a board reset",
                self.robot.url,
            )
        if self.arm_at_start and not self.robot.armed:
            self.robot.arm()
        self.lidar.start()
        self.started_s = self._tick = self.supervisor.now()
        self._halts = self.supervisor.health().halts
        pose = self.poses.update(self.started_s)
        self._pose = pose
        self._frames = FrameGrabber(self.camera)
        return pose

    def step(self) -> Step:
        """One period's work, without waiting (the first call starts the loop if `start()` was not)."""
        if self._frames is None:
            self.start()
        sup, pilot, poses = self.supervisor, self.pilot, self.poses
        if sup.robot is not poses.robot:  # the port was lost and opened again
            poses.use(sup.robot)
        health = sup.health()
        if health.halts != self._halts:
            self._halts = health.halts
            self._halt(health)
        t = sup.now()
        pose = self._pose_now(t, health)
        for scan in self._scans():
            pilot.on_scan(scan, poses.at(scan.time_s + scan.duration_s / 2), pose_at=poses.at)
        frame = self._frame()
        if frame is not None:
            track = pilot.on_frame(frame, poses.at(frame.time_s))
            if track is not None:
                self._track = track.state
        started = time.thread_time()
        linear, angular, mode = pilot.command(pose)
        decide_s = time.thread_time() - started
        driven = health.armed and sup.drive(linear, angular, clamp=True)
        if not health.armed and health.link == LINK_LOST:
            sup.stop_driving()  # zero speed, renewed: nothing drives while nobody can see it
        self._driving = driven
        rearm_due = self.rearm and not health.armed and health.link == LINK_UP and t >= self._rearm_at
        if rearm_due and not sup.arm():
            self._rearm_at = t + REARM_RETRY_S
        return Step(pose, linear, angular, mode, self._track, decide_s, health, driven)

    def _halt(self, health: Health) -> None:
        """The robot stopped being armed and reachable: the pilot stops, the command is cleared."""
        if self._driving:
            self.failsafes += 1
            if health.failsafe is not None and self._pose is not None:
                self.last_failsafe = self._explain(self._pose) or self.last_failsafe
        self._driving = False
        if isinstance(self.pilot, Halting):
            self.pilot.halt(health.halt_why)
        self.supervisor.stop_driving()

    def _pose_now(self, t: float, health: Health) -> Pose:
        """The pose now; while the port is gone, the last one held."""
        last = self._pose
        if health.link in (LINK_RECONNECTING, LINK_CLOSED) and last is not None:
            return last.moved_to(t, last.xyt)
        try:
            self._pose = self.poses.update(t)
        except RoverLinkError:
            if last is None:
                raise
            return last.moved_to(t, last.xyt)
        return self._pose

    def _scans(self) -> list[LidarScan]:
        if "lidar" in self.sensor_errors:
            return []
        try:
            return self.lidar.poll()
        except (RoverLinkError, OSError) as exc:
            self._sensor_failed("lidar", exc)
            return []

    def _frame(self) -> CameraFrame | None:
        frames = self._frames
        if frames is None or "camera" in self.sensor_errors:
            return None
        try:
            frame = frames.latest()
        except (RoverLinkError, OSError) as exc:
            self._sensor_failed("camera", exc)
            return None
        if frames.error is not None:
            self._sensor_failed("camera", frames.error)
        return frame

    def _sensor_failed(self, name: str, error: BaseException | str) -> None:
        self.sensor_errors[name] = str(error)
        log.error("%s stopped: %s (the loop goes on without it)", name, error)

    def _explain(self, pose: Pose) -> str | None:
        reason = self.robot.failsafe
        if reason is None:
            return None
        explain = getattr(self.pilot, "explain_failsafe", None)  # optional: pilots that see the scan
        return str(explain(reason, pose)) if callable(explain) else describe_failsafe(reason)

    def wait(self) -> None:
        """Sleep (on the robot's clock) until the next period; a loop held up longer starts afresh."""
        now = self.supervisor.now()
        self._tick = max(self._tick + self.period_s, now - self.period_s)
        self.supervisor.sleep(max(0.0, self._tick - now))

    def stop(self) -> None:
        """Stop the robot, the lidar and the camera reader (what fails of them is left to close)."""
        if self._frames is not None:
            self._frames.close()
        self.supervisor.stop_driving()
        with contextlib.suppress(RoverLinkError, OSError):
            self.lidar.stop()

    def __enter__(self) -> ControlLoop:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()
