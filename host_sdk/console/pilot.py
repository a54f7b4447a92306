"""The pilot a console drives: the browser's teleop, arming and target, and the follow behaviour.

Each control period it takes what the driving browser asked for (`Hub.take`) and shows what the
robot sees (`Hub.show_frame`, `Hub.show_state`). A box drawn on a frame starts a tracker on that very
frame (the hub still holds it) and the newest frames carry it on; a detection clicked does the
same for a person or a face (`ClassTracker`, which detects the kind again when it is lost).

What drives, in order: nothing while disarmed; the browser's drive command while it is fresh
(it lapses after the board's watchdog period, so a frozen tab stops the robot), limited by the
obstacle guard (`TeleopGuard`, the follow behaviour's footprint and margins on its filtered scan)
unless the user holds the override; the follow behaviour while following; else standing still.
Following ends when the driving browser's keep-alive lapses (unless the console runs autonomous) and
whenever the robot stops being armed and reachable (`halt`: a failsafe, a board reset, a lost link,
STOP), and the drive command with it: arming again never drives off. Arming runs on the
supervisor's thread (`Supervisor.arm_soon`): an ARM with no answer never holds the loop, and its
refusal stays on the page until dismissed.
"""

from __future__ import annotations

import math
from typing import Any

from host_sdk.autonomy.guard import Guarded, TeleopGuard
from host_sdk.autonomy.pilot import FollowPilot, PoseAt
from host_sdk.console.hub import Drive, Hub, Requests
from host_sdk.console.status import LinkLines, Rate, link_view
from host_sdk.geometry import RobotGeometry
from host_sdk.perception.class_tracker import ClassTracker, FrameTracker
from host_sdk.perception.detectors import KINDS
from host_sdk.perception.tracking import Track, Tracker, TrackState
from host_sdk.pose import Pose
from host_sdk.robot import Robot
from host_sdk.sensors import CameraFrame, LidarScan
from host_sdk.supervisor import Health, Supervisor
from protocol.generated.enums import FailsafeReason

Image = Any
SCAN_POINTS = 360
"""At most this many scan points go to the page per revolution (one per degree)."""


class NoTarget:
    """The tracker before a target is chosen: never finds anything."""

    def update(self, image: Image, time_s: float, *, rotation_rad: float = 0.0) -> Track:
        return self.detect(image, time_s)

    def detect(self, image: Image, time_s: float) -> Track:
        return Track(TrackState.LOST, time_s, None, 0.0, None, None, 0.0)


class ConsolePilot:
    name = "console"

    def __init__(
        self,
        hub: Hub,
        robot: Robot | Supervisor,
        geometry: RobotGeometry,
        *,
        target_height_m: float | None = None,
        follow_gap_m: float | None = None,
        max_speed_m_s: float = 0.45,
        tracker: FrameTracker | None = None,
    ) -> None:
        self.hub = hub
        self.supervisor = robot if isinstance(robot, Supervisor) else Supervisor(robot)
        self.geometry = geometry
        self.target_height_m = target_height_m
        self.follow = FollowPilot.with_tracker(
            geometry, tracker or NoTarget(), follow_gap_m=follow_gap_m, max_speed_m_s=max_speed_m_s
        )
        follower = self.follow.follower
        self.guard = TeleopGuard(
            follower.footprint, follower.avoider.params, min_turn_radius_m=geometry.min_turn_radius_m
        )
        self.guarded: Guarded | None = None
        """What the guard made of the last teleop command (None: not driving by hand)."""
        self.following = False
        self.mode = "idle"
        self.health: dict[str, Any] = {}
        """Extra status lines for the page (rates, errors): the program fills it in."""
        self.ended = ""
        """Why following ended by itself last (the keep-alive lapsed, a failsafe...), for the page."""
        self._frame: CameraFrame | None = None
        self._link = LinkLines()
        self._scan_shown: object | None = None
        self._rates = {"scans": Rate(), "camera": Rate()}
        self._failsafe: tuple[FailsafeReason, str] | None = None

    @property
    def robot(self) -> Robot:
        return self.supervisor.robot

    # -- the Pilot protocol -----------------------------------------------------------------------------
    def on_scan(self, scan: LidarScan, pose: Pose, *, pose_at: PoseAt | None = None) -> None:
        self._rates["scans"].tick(scan.time_s)
        self.follow.on_scan(scan, pose, pose_at=pose_at)

    def on_frame(self, frame: CameraFrame, pose: Pose) -> Track | None:
        self._frame = frame
        self._rates["camera"].tick(frame.time_s)
        track = self.follow.on_frame(frame, pose)
        overlay: dict[str, Any] = {"state": track.state.value if self.has_target else None}
        if track.box is not None:
            overlay["box"] = [round(v, 1) for v in track.box]
            overlay["confidence"] = round(track.confidence, 3)
        tracker = self.follow.tracker
        if isinstance(tracker, ClassTracker):
            overlay["detections"] = [[round(v, 1) for v in d.box] for d in tracker.detections]
        self.hub.show_frame(frame.image, frame.time_s, overlay, jpeg=frame.jpeg, device_time_s=frame.device_time_s)
        return track

    def command(self, pose: Pose) -> tuple[float, float, str]:
        asked = self.hub.take()
        self._apply(asked)
        health = self.supervisor.health()
        linear, angular, mode = 0.0, 0.0, "idle"
        self.guarded = None
        if not health.armed:
            mode = "disarmed"
        elif asked.drive is not None:
            seen = self.follow.scans.seen_from(pose)
            points, age = (None, None) if seen is None else seen
            self.guarded = self.guard.limit(
                asked.drive.linear_m_s, self._steerable(asked.drive), points, age_s=age, override=asked.drive.override
            )
            linear, angular, mode = self.guarded.linear_m_s, self.guarded.angular_rad_s, "teleop"
        elif self.following and self.has_target:
            linear, angular, mode = self.follow.command(pose)
        self.mode = mode
        self._show(pose, (linear, angular), health)
        return linear, angular, mode

    def halt(self, why: str) -> None:
        """The robot stopped being armed and reachable: following ends and the drive command goes."""
        if self.following:
            self._end_following(why)
        self.hub.post(drive=None)

    def _end_following(self, why: str) -> None:
        self.following = False
        self.ended = f"following ended: {why}"

    def _steerable(self, drive: Drive) -> float:
        """The turn rate asked, as a car can drive it. The page's left/right is the steering: the
        wheels turn that way whichever way the car drives (backing with "right" swings the nose left,
        as a steering wheel does); none standing still, and no tighter than the steering's tightest
        circle. A differential drive turns as asked."""
        r = self.geometry.min_turn_radius_m
        if r <= 0:
            return drive.angular_rad_s
        asked = -drive.angular_rad_s if drive.linear_m_s < 0 else drive.angular_rad_s
        most = abs(drive.linear_m_s) / r
        return max(-most, min(most, asked))

    # -- requests -------------------------------------------------------------------------------------
    @property
    def has_target(self) -> bool:
        return not isinstance(self.follow.tracker, NoTarget)

    def _apply(self, asked: Requests) -> None:
        camera = self.geometry.camera
        if asked.target_kind is not None and asked.target_kind in KINDS:
            self.follow.tracker = ClassTracker(asked.target_kind, camera)
        if asked.select is not None:
            frame, box = asked.select.frame, asked.select.box
            if isinstance(self.follow.tracker, ClassTracker):  # a detection clicked: that one, by its kind
                tracker = self.follow.tracker
                tracker.last_box = box
                tracker.tracker = Tracker.from_region(
                    frame.image, box, camera, height_m=tracker.height_m, time_s=frame.time_s
                )
            else:
                self.follow.tracker = Tracker.from_region(
                    frame.image, box, camera, height_m=self.target_height_m, time_s=frame.time_s
                )
        if asked.follow is not None:
            self.following = asked.follow
            self.ended = ""
        if self.following and not asked.driver_alive:
            self._end_following("the driving browser stopped keeping it alive (closed, frozen or hidden)")
        if asked.arm:  # also while the host still believes it armed: tried, and a refusal says why
            self.supervisor.arm_soon()

    def _show(self, pose: Pose, motion: tuple[float, float], health: Health) -> None:
        scan = self.follow.last_scan
        rates = {f"{name} rate": text for name, r in self._rates.items() if (text := r.describe(name)) is not None}
        state: dict[str, Any] = {
            "armed": health.armed,
            "mode": self.mode,
            "following": self.following,
            "track": None
            if self.follow.last_track is None or not self.has_target
            else self.follow.last_track.state.value,
            "pose": {"x": round(pose.x_m, 3), "y": round(pose.y_m, 3), "theta": round(pose.theta_rad, 4)},
            "failsafe": health.failsafe,
            "failsafe_text": self._failsafe_text(pose),
            "guard": None if self.guarded is None else {"state": self.guarded.state.value, "text": self.guarded.text},
            "link": link_view(health),
            "ended": self.ended,
            "autonomous": self.hub.autonomous,
            "health": {**self._link.lines(self.robot, health, pose.time_s), **rates, **self.health},
            "motion": {"linear": round(motion[0], 3), "angular": round(motion[1], 3)},
        }
        if scan is not None and scan is not self._scan_shown:  # a new revolution: only then (it is large)
            self._scan_shown = scan
            x, y = scan.points_xy()
            keep = [(round(float(a), 3), round(float(b), 3)) for a, b in zip(x, y, strict=True) if math.isfinite(a)]
            step = max(1, len(keep) // SCAN_POINTS)
            state["scan"] = {"points": keep[::step], "range_m": 4.0, "footprint": self._footprint()}
        self.hub.show_state(**state)

    def explain_failsafe(self, reason: FailsafeReason, pose: Pose) -> str:
        """`reason` in words, naming what the scan shows inside the footprint's margin."""
        return self.follow.explain_failsafe(reason, pose)

    def _failsafe_text(self, pose: Pose) -> str | None:
        """The failsafe explained when it is entered, and kept while it lasts (the scan of that moment
        says what was touched; later ones may have lost it)."""
        reason = self.robot.failsafe
        if reason is None:
            self._failsafe = None
        elif self._failsafe is None or self._failsafe[0] is not reason:
            self._failsafe = (reason, self.explain_failsafe(reason, pose))
        return None if self._failsafe is None else self._failsafe[1]

    def _footprint(self) -> list[tuple[float, float]]:
        fp = self.geometry.footprint
        r, cx = fp.radius_m, fp.x_m
        return [
            (round(cx + r * math.cos(a), 3), round(r * math.sin(a), 3))
            for a in (i * 2 * math.pi / 16 for i in range(16))
        ]
