"""Wheel odometry + the IMU's gyro in the SDK's EKF (host_sdk.fusion.PoseEkf), fed in time order
from two threads: the node's `odometry/filtered`. No ROS here (roverlink.ros2.fused publishes it).

FEEDBACK samples arrive on the SDK's I/O thread, IMU samples on the IMU's thread, each stamped on
the robot's clock (`FeedbackSample.host_time_s`; an IMU sample's time mapped from its port's clock,
see `imu_time`). The EKF needs them in time order: a step fused before the gyro samples of its
interval are in would have to guess the turn. So both are queued and fused up to the time both
streams have reached (the older stream waits at most MAX_LAG_S for the other: a silent IMU does
not stop odometry, whose steps then go by the wheels alone). The caller holds one lock around
every call.
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass
from typing import Any

from host_sdk.errors import CommandRangeError
from host_sdk.fusion import EkfParams, FusedPose, OdometryIncrements, PoseEkf
from host_sdk.fusion.ekf import B
from roverlink.ros2.params import BridgeParams

GYRO, STEP, ANCHOR = 0.0, 1.0, 2.0
"""Kinds of queued items: a gyro rate; an odometry step; the first odometry sample at a set pose."""
MAX_LAG_S = 0.2
"""How long a stream's samples wait for the other stream to reach their time."""
GYRO_STALE_S = 0.5
"""An odometry step this long after the last gyro sample takes its turn rate from the wheels."""
RESYNC_SAMPLES = 25
"""PoseGate: after a set pose, at most this many samples are skipped waiting for the new pose."""


@dataclass(frozen=True, slots=True)
class FusedOdometry:
    """One fused odometry step: the EKF's pose at `time_s` (robot clock) and the body's twist."""

    time_s: float
    x_m: float
    y_m: float
    theta_rad: float
    covariance: tuple[float, ...]
    """Row-major 3 x 3 covariance of (x, y, theta)."""
    linear_m_s: float
    """From the wheel speeds the board measured."""
    angular_rad_s: float
    """The gyro's rate less the EKF's bias estimate (the wheels' while the gyro is silent)."""
    angular_variance: float | None
    """Of the gyro's rate: its noise plus the bias estimate's variance (None: from the wheels)."""
    slipping: bool


def imu_expected(params: BridgeParams, emu_options: Any) -> bool:
    """The node will have an IMU: `imu_url`, or an emu:// URL with `imu=...`."""
    emulated = emu_options is not None and emu_options.sensors is not None and emu_options.sensors.imu
    return bool(params.imu_url or emulated)


def check_tf_from(params: BridgeParams, has_imu: bool) -> None:
    """`tf_from: fused` without an IMU is refused at start: the transform would never be published."""
    if params.tf_from == "fused" and not has_imu:
        raise CommandRangeError(
            "parameter tf_from",
            "fused",
            "'odom', or 'fused' with an IMU (set imu_url, or use an emu:// URL with imu=jy901)",
        )


class PoseGate:
    """After the pose is set, FEEDBACK samples integrated before it may still be on their way (the
    SDK runs callbacks after its lock is released): they are skipped until the first one at the new
    pose (the odometry's first sample after a reset only re-anchors the counts, so it is exactly
    there); after RESYNC_SAMPLES the gate opens anyway."""

    def __init__(self) -> None:
        self._awaiting: tuple[float, float, float] | None = None
        self._skipped = 0

    def expect(self, x_m: float, y_m: float, theta_rad: float) -> None:
        self._awaiting = (x_m, y_m, theta_rad)
        self._skipped = 0

    def accept(self, pose: tuple[float, float, float]) -> bool:
        if self._awaiting is None:
            return True
        if pose != self._awaiting and self._skipped < RESYNC_SAMPLES:
            self._skipped += 1
            return False
        self._awaiting = None
        return True


def imu_time(sample_t: float, port_now: float, robot_now: float) -> float:
    """An IMU sample's time on the robot's clock: its port's clock and the robot's are read one
    after the other, so their offset is known to the microseconds between the reads. Both are
    the host's monotonic clock for real ports and for `emu://` on the wall clock, and the same
    emulator's virtual time with `clock=virtual`: the offset is then about zero; an IMU on a real
    port beside an emulated robot on its virtual clock is mapped across."""
    return sample_t + (robot_now - port_now)


class Fusion:
    """The EKF and the queue of samples not yet fused. Not thread-safe: call it under one lock."""

    def __init__(self, start_s: float, *, gyro_variance: float, params: EkfParams | None = None) -> None:
        if not (math.isfinite(gyro_variance) and gyro_variance >= 0):
            raise CommandRangeError("gyro_variance", gyro_variance, "a variance >= 0 in (rad/s)^2")
        self.ekf = PoseEkf(params, time_s=start_s)
        self.gyro_variance = gyro_variance
        self._steps = OdometryIncrements()
        self._queue: list[tuple[float, int, tuple[float, ...]]] = []
        self._seq = itertools.count()
        self._newest_odometry: float | None = None
        self._newest_gyro: float | None = None
        self._gyro: tuple[float, float] | None = None
        """(time, rate) of the last gyro sample fused."""
        self._gate = PoseGate()
        self._anchoring = False

    # -- inputs ---------------------------------------------------------------------------------------
    def add_odometry(
        self, time_s: float, pose: tuple[float, float, float], linear_m_s: float, angular_rad_s: float
    ) -> list[FusedOdometry]:
        """One FEEDBACK: the wheel odometry's pose (x, y, theta) and the measured body twist."""
        if not self._gate.accept(pose):
            return []  # integrated before the pose was set: its step would jump back
        ds, turn = self._steps.step(*pose)
        if self._anchoring:  # the first sample at the set pose: the EKF's pose is this one's
            self._anchoring = False
            self._push(time_s, (ANCHOR, *pose, linear_m_s, angular_rad_s))
        else:
            self._push(time_s, (STEP, ds, turn, linear_m_s, angular_rad_s))
        self._newest_odometry = max(time_s, self._newest_odometry or time_s)
        return self._drain(self._watermark())

    def add_gyro(self, time_s: float, rate_rad_s: float) -> list[FusedOdometry]:
        """One IMU sample's z rate (rad/s, counter-clockwise) at `time_s` on the robot's clock."""
        if not math.isfinite(rate_rad_s):
            raise CommandRangeError("rate_rad_s", rate_rad_s, "a finite rate in rad/s")
        self._push(time_s, (GYRO, rate_rad_s))
        self._newest_gyro = max(time_s, self._newest_gyro or time_s)
        return self._drain(self._watermark())

    def set_pose(self, x_m: float, y_m: float, theta_rad: float) -> list[FusedOdometry]:
        """Fuse what is queued, then put the pose at (x, y, theta); the caller sets the wheel
        odometry to the same pose, whose first sample there is the EKF's new start (what the gyro
        turned before it is dropped with the counts). Returns the steps fused before."""
        flushed = self._drain(math.inf)
        self.ekf.set_pose(x_m, y_m, theta_rad)
        self._gate.expect(x_m, y_m, theta_rad)
        self._steps = OdometryIncrements()
        self._anchoring = True
        return flushed

    # -- the queue ------------------------------------------------------------------------------------
    def _push(self, time_s: float, item: tuple[float, ...]) -> None:
        heapq.heappush(self._queue, (time_s, next(self._seq), item))

    def _watermark(self) -> float:
        """Fuse up to here: where both streams have reached, or the newer one less MAX_LAG_S."""
        odo, gyro = self._newest_odometry, self._newest_gyro
        if gyro is None or odo is None:
            return odo if odo is not None else -math.inf  # no IMU yet: the wheels alone, at once
        return max(min(odo, gyro), max(odo, gyro) - MAX_LAG_S)

    def _drain(self, until: float) -> list[FusedOdometry]:
        out = []
        while self._queue and self._queue[0][0] <= until:
            time_s, _, (kind, *values) = heapq.heappop(self._queue)
            if kind == GYRO:
                self.ekf.add_gyro(time_s, values[0])
                self._gyro = (time_s, values[0])
                continue
            if kind == ANCHOR:
                self.ekf.set_pose(values[0], values[1], values[2], time_s=time_s)
                pose = self.ekf.pose
            else:
                pose = self.ekf.add_odometry(time_s, values[0], values[1])
            out.append(self._output(pose, linear=values[-2], angular=values[-1]))
        return out

    def _output(self, pose: FusedPose, *, linear: float, angular: float) -> FusedOdometry:
        gyro, variance = self._gyro, None
        if gyro is not None and abs(pose.time_s - gyro[0]) < GYRO_STALE_S:
            angular = gyro[1] - pose.gyro_bias_rad_s
            variance = self.gyro_variance + float(self.ekf.P[B, B])
        cov = tuple(float(v) for v in pose.covariance.ravel())
        return FusedOdometry(
            pose.time_s, pose.x_m, pose.y_m, pose.theta_rad, cov, linear, angular, variance, pose.slipping
        )

    @property
    def pending(self) -> int:
        """Samples queued, not yet fused."""
        return len(self._queue)
