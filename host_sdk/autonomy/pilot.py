"""A pilot: what turns sensor data into a body twist in a robot program's loop.

A pilot is fed lidar revolutions and camera frames as they arrive (each with the robot's pose at
the time it was taken) and asked for a twist every control period. `FollowPilot` is RoverLink's
follow-while-avoiding behaviour: the scan filter, the motion detector, the camera tracker and the
`Follower` joined up.

    pilot = FollowPilot.for_robot(geometry(profile, robot.kinematics, config=robot.config), template)
    pilot = FollowPilot.for_target(geometry(...), "person")     # or "face": detected, then tracked
"""

from __future__ import annotations

import dataclasses
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from host_sdk.autonomy.follow import Decision, Follower
from host_sdk.autonomy.follow_params import FollowParams
from host_sdk.autonomy.guard import LatestScan, explain_failsafe, within_margin
from host_sdk.geometry import RobotGeometry
from host_sdk.perception import AvoidanceParams, MotionDetector, Mover, ObstacleScan, ScanFilter
from host_sdk.perception.class_tracker import ClassTracker, FrameTracker
from host_sdk.perception.tracking import Track, Tracker
from host_sdk.pose import Pose, PoseAt
from host_sdk.sensors import CameraFrame, LidarScan
from protocol.generated.enums import FailsafeReason

# PoseAt lives in host_sdk.pose; pilots have always found it here too.
__all__ = ["FollowPilot", "Halting", "Pilot", "PoseAt", "follow_gap"]
TRACK_FRESH_S = 0.3
"""A track older than this is not steered by (the camera stalled or the tracker lags)."""


class Pilot(Protocol):
    name: str

    def on_scan(self, scan: LidarScan, pose: Pose, *, pose_at: PoseAt | None = None) -> None:
        """A revolution, the pose at its mid-time, and (to de-skew it) the pose at any recent time."""
        ...

    def on_frame(self, frame: CameraFrame, pose: Pose) -> Track | None: ...

    def command(self, pose: Pose) -> tuple[float, float, str]:
        """(linear m/s, angular rad/s, what it is doing) at `pose.time_s`."""
        ...


@runtime_checkable
class Halting(Protocol):
    """A pilot that drives by itself and must stop when the robot stops being armed and reachable (a
    failsafe, a board reset, a lost link, STOP): `ControlLoop` calls `halt(why)` then."""

    def halt(self, why: str) -> None: ...


def follow_gap(geometry: RobotGeometry) -> float:
    """The default gap to keep: 0.5 m for a differential drive, 0.9 m for an Ackermann robot, which
    cannot turn on the spot: from farther back a target that turns moves less across the image, and
    the car has room to drive the arc that keeps it in view."""
    return 0.9 if geometry.min_turn_radius_m > 0 else 0.5


class FollowPilot:
    """Scan filter + motion detector + tracker + `Follower`."""

    name = "roverlink"

    def __init__(self, scan_filter: ScanFilter, tracker: FrameTracker, follower: Follower) -> None:
        self.scan_filter = scan_filter
        self.scans = LatestScan(scan_filter)
        self.tracker = tracker
        self.follower = follower
        self.motion = MotionDetector()
        self.movers: tuple[Mover, ...] = ()
        self.decision: Decision | None = None
        self.last_frame: CameraFrame | None = None
        self.last_track: Track | None = None
        """The latest frame and track (for recording and live views; the scan: `last_scan`)."""
        self._track: tuple[Track, Pose] | None = None
        self._frame_pose: Pose | None = None

    @classmethod
    def for_robot(
        cls,
        geometry: RobotGeometry,
        template: NDArray[np.uint8],
        *,
        follow_gap_m: float | None = None,
        max_speed_m_s: float = 0.45,
        target_height_m: float | None = None,
    ) -> FollowPilot:
        """The pilot for a robot of `geometry` following what `template` (BGR, or a BGRA cut-out) shows;
        `target_height_m`, the target's real height, gives the tracker a range estimate."""
        tracker = Tracker(template, geometry.camera, height_m=target_height_m)
        return cls.with_tracker(geometry, tracker, follow_gap_m=follow_gap_m, max_speed_m_s=max_speed_m_s)

    @classmethod
    def for_target(
        cls,
        geometry: RobotGeometry,
        kind: str,
        *,
        follow_gap_m: float | None = None,
        max_speed_m_s: float = 0.45,
        target_height_m: float | None = None,
    ) -> FollowPilot:
        """The pilot following a "person" or a "face": detected, tracked, and detected again when lost
        (`ClassTracker`); `target_height_m` defaults to the kind's (1.7 m, 0.16 m)."""
        tracker = ClassTracker(kind, geometry.camera, height_m=target_height_m)
        return cls.with_tracker(geometry, tracker, follow_gap_m=follow_gap_m, max_speed_m_s=max_speed_m_s)

    @classmethod
    def with_tracker(
        cls,
        geometry: RobotGeometry,
        tracker: FrameTracker,
        *,
        follow_gap_m: float | None = None,
        max_speed_m_s: float = 0.45,
    ) -> FollowPilot:
        """The pilot for a robot of `geometry` fed by any tracker (a `Tracker` or a `ClassTracker`)."""
        gap = follow_gap(geometry) if follow_gap_m is None else follow_gap_m
        params = FollowParams(follow_gap_m=gap, max_speed_m_s=max_speed_m_s)
        follower = Follower(
            geometry.footprint,
            geometry.camera,
            min_turn_radius_m=geometry.min_turn_radius_m,
            avoidance=AvoidanceParams(),
            params=params,
            curvatures=geometry.curvatures,
            accel_m_s2=geometry.accel_m_s2,
        )
        return cls(ScanFilter(geometry.lidar_mount), tracker, follower)

    @property
    def last_scan(self) -> ObstacleScan | None:
        """The latest filtered scan."""
        return self.scans.scan

    def on_scan(self, scan: LidarScan, pose: Pose, *, pose_at: PoseAt | None = None) -> None:
        obstacles = self.scans.update(scan, pose, pose_at=pose_at)
        self.movers = self.motion.update(obstacles, pose.xyt)

    def on_frame(self, frame: CameraFrame, pose: Pose) -> Track:
        turned = 0.0 if self._frame_pose is None else pose.theta_rad - self._frame_pose.theta_rad
        self._frame_pose = pose
        track = self.tracker.update(frame.image, frame.time_s, rotation_rad=turned)
        self._track = (track, pose)
        self.last_frame, self.last_track = frame, track
        return track

    def command(self, pose: Pose) -> tuple[float, float, str]:
        seen = self.scans.seen_from(pose)  # the latest revolution, moved to where the robot is now
        if seen is None:
            return 0.0, 0.0, "waiting"
        (px, py), _ = seen
        track = None
        if self._track is not None:
            tr, seen_at = self._track
            if pose.time_s - tr.time_s < TRACK_FRESH_S:
                track = tr
                if tr.bearing_rad is not None:  # the robot has turned since the frame was taken
                    track = dataclasses.replace(tr, bearing_rad=tr.bearing_rad - (pose.theta_rad - seen_at.theta_rad))
        # The follower estimates the speed it plans from from successive poses, as its planner was
        # tuned with: planning from the board's measured speed (pose.linear_m_s) changed decisions
        # and led to contacts in 2 of 20 benchmark worlds (docs/autonomy.md).
        decision = self.follower.step(pose.time_s, px, py, track, pose.xyt, movers=self.movers)
        self.decision = decision
        return decision.linear_m_s, decision.angular_rad_s, decision.mode.value

    def explain_failsafe(self, reason: FailsafeReason, pose: Pose) -> str:
        """`reason` in words, naming what the latest scan shows inside the footprint's margin."""
        seen = self.scans.seen_from(pose)
        follower = self.follower
        margin = follower.avoider.params.margin_m
        near = None if seen is None else within_margin(seen[0], follower.footprint, margin)
        return explain_failsafe(reason, near, margin)
