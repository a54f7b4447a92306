"""Where the target is this step, whether or not the camera has it.

1. The camera has it: its bearing (and range estimate) is matched against the scan (`locate_target`).
2. The camera does not (beside the robot, too close, turned away from): its returns are followed in
   the scan from where the last fix predicts it, for as long as each revolution finds it again;
   beside clutter the cluster is ambiguous, and a mover there confirms it.
3. Lost from the scan too: something moving in the scan is most likely the target (nothing else in
   a room walks). Following it turns the camera to it, and the tracker's re-detection takes over.
4. Doubt: what the camera has had in its picture for `doubt_s` in all (the looks need not be one
   after another) without seeing the target is not the target (a false mover, a cylinder of its
   size), and neither is a mover the camera has not confirmed within `confirm_s` of taking it (one
   the robot cannot turn to, or hidden) while it is farther than `near_m` (one that close is kept:
   a moving body beside the robot is one to keep clear of). It is dropped, and not taken again for
   `reject_s`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from host_sdk.autonomy.memory import TargetMemory, to_world
from host_sdk.autonomy.target import TargetFix, locate_target
from host_sdk.body import CameraModel
from host_sdk.perception.motion import Mover
from host_sdk.perception.tracking import Track
from host_sdk.pose import Pose2D

F64 = NDArray[np.float64]


class TargetFinder:
    def __init__(
        self,
        camera: CameraModel,
        *,
        target_size_m: float,
        coast_s: float,
        doubt_s: float,
        reject_s: float,
        confirm_s: float,
        near_m: float = 1.0,
    ) -> None:
        self.camera = camera
        self.target_size_m = target_size_m
        self.coast_s = coast_s
        self.doubt_s = doubt_s
        self.reject_s = reject_s
        self.confirm_s = confirm_s
        self.near_m = near_m
        self.memory = TargetMemory(target_size_m)
        self._t = 0.0
        self._scan_ok = True
        """False once the camera, looking at what the scan follows, did not see the target there."""
        self._doubt = 0.0
        self._unconfirmed_since = math.inf
        """When the scan began following a mover the camera has not confirmed since."""
        self._rejected: list[tuple[float, float, float]] = []
        """(until, x, y) in the odometry frame: what the camera looked at and found not the target."""

    def find(
        self, t: float, px: F64, py: F64, track: Track | None, pose: Pose2D, *, movers: Sequence[Mover] = ()
    ) -> TargetFix | None:
        """The target's fix now (base frame), or None; what was found is remembered."""
        dt, self._t = max(0.0, t - self._t), t
        mem = self.memory
        if track is not None and track.found:
            self._doubt = 0.0
            if track.bearing_rad is not None:
                fix = locate_target(px, py, self.camera, track.bearing_rad, track.range_m, size_m=self.target_size_m)
                if fix is not None:
                    mem.camera_seen = t
                    mem.remember(t, fix, pose)
                    self._scan_ok = True
                    self._unconfirmed_since = math.inf
                    return fix
        self._rejected = [r for r in self._rejected if r[0] > t]
        fix = None
        predicted = mem.predicted(t, pose, self.coast_s)
        if self._scan_ok and predicted is not None and mem.seen is not None:
            fix = mem.lidar_fix(px, py, predicted, gate_m=0.3 + 0.3 * (t - mem.seen[0]))
            if fix is None:
                fix = mem.mover_fix(px, py, self._unrejected(movers), pose, near=predicted, gate_m=0.5)
        if fix is None and predicted is None:
            fix = mem.mover_fix(px, py, self._unrejected(movers), pose, compact=True)
            self._doubt = 0.0
            if fix is not None:
                self._unconfirmed_since = t
        if fix is None:
            return None
        cam = self.camera
        looking = abs(cam.off_axis_rad(fix.x_m, fix.y_m)) < 0.85 * cam.half_fov_rad and fix.range_m < 3.5
        if looking and track is not None and not track.found:
            # Held, not cleared, while it is out of the picture: only the camera seeing the target
            # clears it (a false target skirting the edge of the view would otherwise never be dropped).
            self._doubt += dt
        # Unconfirmed but within reach is kept: a body that close, moving, is not one to forget.
        unconfirmed = t - self._unconfirmed_since > self.confirm_s and fix.range_m > self.near_m
        if self._doubt > self.doubt_s or unconfirmed:
            self._rejected.append((t + self.reject_s, *to_world(pose, fix.x_m, fix.y_m)))
            self._scan_ok, self._doubt, self._unconfirmed_since = False, 0.0, math.inf
            mem.seen = None  # nor steered for where it would be now
            return None
        self._scan_ok = True
        mem.remember(t, fix, pose)
        return fix

    def _unrejected(self, movers: Sequence[Mover]) -> list[Mover]:
        return [m for m in movers if all(math.hypot(m.x_m - x, m.y_m - y) > 0.5 for _, x, y in self._rejected)]
