"""A robot program's control loop: sensors in, a pilot's twist out, every control period.

    loop = ControlLoop(robot, pilot, lidar=lidar, camera=camera, imu=imu)   # imu: optional
    with loop:                                  # arms, starts the lidar; stops the robot at the end
        while robot.now() - loop.started_s < 60:
            step = loop.step()                  # one period's work; step.mode says what it does
            loop.wait()                         # until the next period

Per period (`period_s`, 20 Hz by default): complete lidar revolutions, the newest camera frame and
the IMU's samples are read without waiting; each goes to the pilot with the robot's pose at the time
it was taken (`PoseSource`: the EKF's with an IMU, else wheel odometry); the pilot's twist is sent
every period (setpoints are cheap, and renewing them keeps the board's watchdog fed). A failsafe
(e.g. pushing against something) is counted, put in words (`last_failsafe`: with a pilot that has
`explain_failsafe`, such as `FollowPilot`, naming what the lidar sees touching the footprint) and
the robot re-armed (unless `rearm=False`: then arming is left to the user).

Waiting is `robot.sleep()`, so the same loop runs on a real robot (wall clock) and on the emulator's
virtual clock (as fast as the CPU allows, deterministic).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from host_sdk.autonomy.pilot import Pilot
from host_sdk.errors import NotArmedError
from host_sdk.failsafe import describe_failsafe
from host_sdk.fusion.source import PoseSource
from host_sdk.perception.tracking import TrackState
from host_sdk.pose import RobotPose
from host_sdk.robot import Robot
from host_sdk.sensors import CameraSource, FrameGrabber, Jy901, Lidar


@dataclass(frozen=True, slots=True)
class Step:
    """What one period did."""

    pose: RobotPose
    linear_m_s: float
    angular_rad_s: float
    mode: str
    """What the pilot is doing (its own word: "follow", "search", ...)."""
    track: TrackState | None
    """The tracker's state at the newest frame so far (None before the first)."""
    decide_s: float
    """CPU time the pilot took to decide."""


class ControlLoop:
    def __init__(self, robot: Robot, pilot: Pilot, *, lidar: Lidar, camera: CameraSource, imu: Jy901 | None = None,
                 period_s: float = 0.05, rearm: bool = True) -> None:  # fmt: skip
        self.robot = robot
        self.rearm = rearm
        """Arm at the start and after a failsafe. False: arming is the user's (a console's Arm
        button); a robot disarmed, by a failsafe or by the user, stays so until then."""
        self.pilot = pilot
        self.lidar = lidar
        self.camera = camera
        self.period_s = period_s
        self.poses = PoseSource(robot, imu)
        self.failsafes = 0
        """Failsafes met (and re-armed after) while driving."""
        self.last_failsafe: str | None = None
        """The last of them in words (what it means, and what the lidar saw at the footprint)."""
        self.started_s = 0.0
        self._frames: FrameGrabber | None = None
        self._track: TrackState | None = None
        self._tick = 0.0

    def start(self) -> RobotPose:
        """Arm (unless `rearm` is False), start the lidar and the camera reader; the pose at the start."""
        if self.rearm and not self.robot.armed:
            self.robot.arm()
        self.lidar.start()
        self.started_s = self._tick = self.robot.now()
        pose = self.poses.update(self.started_s)
        self._frames = FrameGrabber(self.camera)
        return pose

    def step(self) -> Step:
        """One period's work, without waiting (the first call starts the loop if `start()` was not)."""
        if self._frames is None:
            self.start()
        assert self._frames is not None
        robot, pilot, poses = self.robot, self.pilot, self.poses
        t = robot.now()
        pose = poses.update(t)
        for scan in self.lidar.poll():
            pilot.on_scan(scan, poses.at(scan.time_s + scan.duration_s / 2), pose_at=poses.at)
        frame = self._frames.latest()
        if frame is not None:
            track = pilot.on_frame(frame, poses.at(frame.time_s))
            if track is not None:
                self._track = track.state
        started = time.thread_time()
        linear, angular, mode = pilot.command(pose)
        decide_s = time.thread_time() - started
        if robot.armed or self.rearm:
            try:
                robot.drive(linear, angular, clamp=True)
            except NotArmedError:  # a failsafe (e.g. pushing against something): count it, re-arm
                self.failsafes += 1
                self.last_failsafe = self._explain(pose) or self.last_failsafe
                if self.rearm:
                    robot.arm()
        return Step(pose, linear, angular, mode, self._track, decide_s)

    def _explain(self, pose: RobotPose) -> str | None:
        reason = self.robot.failsafe
        if reason is None:
            return None
        explain = getattr(self.pilot, "explain_failsafe", None)  # optional: pilots that see the scan
        return str(explain(reason, pose)) if callable(explain) else describe_failsafe(reason)

    def wait(self) -> None:
        """Sleep (on the robot's clock) until the next period."""
        self._tick += self.period_s
        self.robot.sleep(max(0.0, self._tick - self.robot.now()))

    def stop(self) -> None:
        """Stop the robot, the lidar and the camera reader."""
        if self._frames is not None:
            self._frames.close()
        self.robot.stop()
        self.lidar.stop()

    def __enter__(self) -> ControlLoop:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()
