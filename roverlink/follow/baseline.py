"""The PiCar team's published approach as a pilot (host_sdk.autonomy.Pilot), for `roverlink follow
--pilot picar-2018` and the follow benchmark: it gets exactly the inputs RoverLink's FollowPilot gets.
"""

from __future__ import annotations

import math
import warnings
from collections import deque

import numpy as np
from numpy.typing import NDArray

from host_sdk.autonomy.pilot import PoseAt
from host_sdk.perception import CameraModel, LidarMount
from host_sdk.perception.class_tracker import FrameTracker
from host_sdk.perception.scan import bin_points
from host_sdk.perception.tracking import Track, TrackState
from host_sdk.pose import Pose
from host_sdk.sensors import CameraFrame, LidarScan

F64 = NDArray[np.float64]


class PiCarBaseline:
    """The PiCar capstone's published approach, re-implemented from its report.

    - Lidar: a per-beam median over the last 13 revolutions (ROS laser_filters' median filter as the
      team set it, no motion compensation); an obstacle when three consecutive beams just right of
      straight ahead are all under 1.3 m. On "nothing -> something" it turns, opposite to its
      previous turn (left first); on "something -> nothing" it goes straight.
    - Camera: the object's horizontal position about once a second (find_object_2d's rate on the
      Pi), in three zones of the image: left of 280/800 of the width, right of 580/800, else middle;
      the wheels turn towards the zone.
    - Steering in 15 degree steps (one step either way), at a constant speed: the car never stopped.
    - The two run side by side and each sends only when its own state changes; the Arduino keeps the
      latest byte it received (latest wins). They were never combined.

    The detector behind the 1 Hz positions is RoverLink's (the same template, the same re-detection):
    find_object_2d matched ORB-style features, which the emulated target's plain bands do not have;
    giving the baseline a detector that works keeps the comparison about what was published.
    """

    name = "picar-2018"
    THRESHOLD_M = 1.3
    STEER_RAD = math.radians(15)
    WHEELBASE_M = 0.26
    """The PiCar's, to turn a steering angle into a curvature on a differential drive too."""

    def __init__(
        self,
        tracker: FrameTracker,
        camera: CameraModel,
        mount: LidarMount,
        speed_m_s: float,
        *,
        bins: int = 500,
        period_s: float = 1.0,
    ) -> None:
        self.tracker = tracker
        self.camera = camera
        self.mount = mount
        self.speed = speed_m_s
        self.bins = bins
        self.period_s = period_s
        self._scans: deque[F64] = deque(maxlen=13)
        self._obstacle = False
        self._last_turn = "right"  # so that it turns left first, as their code did
        self._zone = "straight"
        self._next_detect = -math.inf
        self.steer = "straight"
        """The latest command sent (what the Arduino holds)."""

    def on_scan(self, scan: LidarScan, pose: Pose, *, pose_at: PoseAt | None = None) -> None:
        """Their filter had no motion compensation: `pose` and `pose_at` are not used."""
        ok = np.isfinite(scan.ranges_m)
        a = scan.angles_rad[ok] + self.mount.yaw_rad
        r = scan.ranges_m[ok]
        self._scans.append(bin_points(r * np.cos(a), r * np.sin(a), self.bins))  # the lidar's own frame
        with warnings.catch_warnings():  # a beam with no return in any revolution: NaN, as it should be
            warnings.simplefilter("ignore", RuntimeWarning)
            ranges = np.nanmedian(np.vstack(self._scans), axis=0)
        # Three consecutive beams straight ahead (their code: the beam at 1..1.5 degrees and the two
        # before it, at the F4's 0.5 degree step).
        front = (self.bins // 2 + np.array([-1, 0, 1])) % self.bins
        seen = bool(np.all(ranges[front] < self.THRESHOLD_M))
        if seen and not self._obstacle:
            self._last_turn = "left" if self._last_turn == "right" else "right"
            self.steer = self._last_turn
        elif not seen and self._obstacle:
            self.steer = "straight"
        self._obstacle = seen

    def on_frame(self, frame: CameraFrame, pose: Pose) -> Track | None:
        if frame.time_s < self._next_detect:
            return None
        self._next_detect = frame.time_s + self.period_s
        track = self.tracker.detect(frame.image, frame.time_s)  # from scratch each time, as find_object_2d
        if track.state is not TrackState.LOST and track.centre is not None:
            u = track.centre[0] / self.camera.width * 800
            zone = "left" if u < 280 else "right" if u > 580 else "straight"
            if zone != self._zone:
                self._zone = zone
                self.steer = zone
        return track

    def command(self, pose: Pose) -> tuple[float, float, str]:
        steer = {"left": self.STEER_RAD, "right": -self.STEER_RAD, "straight": 0.0}[self.steer]
        return self.speed, self.speed * math.tan(steer) / self.WHEELBASE_M, self.steer
