"""FEEDBACK frames -> FeedbackSample: the wire's wrapping counters unwrapped, odometry advanced.

This is the receive path's per-frame work on the host (the session calls `sample()` for every
FEEDBACK of the open session), so it is written to be cheap: no argument checks (the values were
decoded and range-checked by the codec), no allocation beyond the sample itself.
"""

from __future__ import annotations

from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.odometry import Odometry
from host_sdk.pose import Pose
from host_sdk.session.events import OdometryGap
from host_sdk.session.types import FeedbackSample
from host_sdk.timesync import ClockSync, Unwrapper
from protocol.generated.constants import WHEEL_COUNT
from protocol.generated.messages import Feedback

_PER_MILLE = (1000).__rtruediv__  # x -> x / 1000, as map() takes it


def _bits(name: str) -> int:
    """The width of a FEEDBACK counter on the wire (it wraps there)."""
    info = next(f for f in Feedback.FIELDS if f.name == name)
    return int(info.hi - info.lo + 1).bit_length() - 1


_COUNT_BITS, _TICK_BITS = _bits("encoder_counts"), _bits("tick")


class FeedbackTracker:
    """Unwraps counts, MCU time and tick of consecutive FEEDBACK frames of one boot, keeps the
    odometry and the latest sample. The encoder counts are unwrapped here and nowhere else
    (odometry takes them unwrapped)."""

    __slots__ = ("_counts", "_index", "_latest", "_prev_steering", "_stamp", "_tick", "kinematics", "odometry")

    def __init__(self, kinematics: DiffDrive | Ackermann | None = None) -> None:
        self.kinematics = kinematics
        self.odometry: Odometry | None = Odometry(kinematics) if kinematics is not None else None
        self._index = 0
        self._prev_steering = 0.0
        self._counts = [Unwrapper(_COUNT_BITS) for _ in range(WHEEL_COUNT)]
        self._tick = Unwrapper(_TICK_BITS)
        self._latest: FeedbackSample | None = None
        self._stamp = -float("inf")

    @property
    def latest(self) -> FeedbackSample | None:
        """The latest sample (its `received_s` is when the latest FEEDBACK arrived)."""
        return self._latest

    def pose(self) -> Pose | None:
        """The odometry's pose (None without kinematics)."""
        odo = self.odometry
        return odo.pose if odo is not None else None

    def reset_pose(self, x_m: float, y_m: float, theta_rad: float) -> bool:
        """Set the pose (counting goes on from the next sample); False without kinematics."""
        odo = self.odometry
        if odo is None:
            return False
        odo.reset(x_m, y_m, theta_rad)
        return True

    def new_boot(self) -> None:
        """The board rebooted: its counters start again; the pose is kept and the counts re-anchored."""
        self._counts = [Unwrapper(_COUNT_BITS) for _ in range(WHEEL_COUNT)]
        self._tick = Unwrapper(_TICK_BITS)
        if self.odometry is not None:
            self.odometry.reanchor()

    def counts_lost(self, now: float) -> OdometryGap | None:
        """The board was reset (known at `now`): the counts since its last FEEDBACK are lost. The
        odometry records the gap (None without odometry, or before any FEEDBACK)."""
        odo, latest = self.odometry, self._latest
        gap = None
        if odo is not None and latest is not None:
            duration = max(0.0, now - latest.received_s)
            position, heading = odo.gap(duration)  # from the speeds of the last sample
            gap = OdometryGap(duration, position, heading, odo.pose)
        self.new_boot()
        return gap

    def set_kinematics(self, kinematics: DiffDrive | Ackermann | None) -> None:
        """New kinematics (e.g. the configuration changed the wheel size); the pose is kept."""
        pose = self.odometry.pose if self.odometry is not None else None
        self.kinematics = kinematics
        self.odometry = Odometry(kinematics) if kinematics is not None else None
        if pose is not None and self.odometry is not None:
            self.odometry.restore(pose)

    def sample(self, msg: Feedback, now: float, clock: ClockSync) -> FeedbackSample:
        """The FeedbackSample of one FEEDBACK, received at host time `now`."""
        counts = tuple(map(Unwrapper.step, self._counts, msg.encoder_counts))
        mcu_us = clock.unwrap_raw(msg.mcu_time_us)
        steering = msg.steering_mrad / 1000
        # The board's sampling time on the host's clock, never before the previous sample's: the
        # clock fit moves as PONGs arrive (the first from receive time to the fitted line, a queued
        # round trip shifting the line), and consumers of the stamps (tf2, odometry) need order.
        stamp = clock.host_s_of(mcu_us) if clock.synced else now
        self._stamp = stamp = stamp if stamp > self._stamp else self._stamp + 1e-6
        pose: Pose | None = None
        odo = self.odometry
        if odo is not None:
            odo.advance(counts, mcu_us, self._prev_steering, stamp)
            pose = odo.pose
        self._prev_steering = steering
        self._index += 1
        self._latest = sample = FeedbackSample(
            self._index,
            msg.boot_id,
            now,
            stamp,
            mcu_us,
            self._tick.step(msg.tick),
            msg.status,
            msg.failsafe_reason,
            counts,
            tuple(map(_PER_MILLE, msg.wheel_speed_mm_s)),  # mm/s -> m/s
            tuple(map(_PER_MILLE, msg.effort_permille)),
            steering,
            msg.ack_seq,
            pose,
        )
        return sample
