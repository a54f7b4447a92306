"""Kinematics and odometry: exact arcs, wrap-around, lost frames, curvature-keeping scaling."""

from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from host_sdk.kinematics import Ackermann, Arc, DiffDrive, KinematicsError
from host_sdk.odometry import Odometry, integrate_arc
from host_sdk.session.feedback import FeedbackTracker
from host_sdk.timesync import ClockSync, Unwrapper
from protocol.generated import enums, messages

ROBOT = DiffDrive(wheel_radius_m=0.032, track_m=0.2, counts_per_rev=1560)


def test_unwrapping_handles_i32_overflow_both_ways() -> None:
    up = Unwrapper(32)
    assert up(2**31 - 5) == 2**31 - 5
    assert up(-(2**31) + 5) == 2**31 + 5  # 10 counts on, past the wrap
    down = Unwrapper(32)
    down(-(2**31) + 5)
    assert down(2**31 - 5) == -(2**31) - 5  # 10 counts back
    assert Unwrapper(32)(100) == 100


@given(
    st.floats(-2, 2),
    st.floats(-3, 3),
    st.floats(0.01, 5),
    st.integers(1, 200),
)
def test_arc_integration_is_exact_for_constant_curvature(v: float, w: float, duration: float, pieces: int) -> None:
    """One arc or the same arc cut into pieces ends at the same pose (a chord method would not)."""
    whole = integrate_arc(0.3, -0.2, 0.7, Arc(v * duration, w * duration))
    x, y, th = 0.3, -0.2, 0.7
    for _ in range(pieces):
        x, y, th = integrate_arc(x, y, th, Arc(v * duration / pieces, w * duration / pieces))
    assert whole == pytest.approx((x, y, th), abs=1e-9)


def test_full_circle_returns_to_start() -> None:
    radius, ds = 0.5, 2 * math.pi * 0.5
    x, y, th = integrate_arc(1.0, 2.0, 0.0, Arc(ds, ds / radius))
    assert (x, y) == pytest.approx((1.0, 2.0), abs=1e-12)
    assert th == pytest.approx(2 * math.pi)


def test_lost_feedback_frames_lose_no_ticks() -> None:
    """Dropping every other sample gives the same pose: counts are cumulative."""
    full, sparse = Odometry(ROBOT), Odometry(ROBOT)
    left = right = 0
    for k in range(1, 401):
        left += 13
        right += 17 if k <= 200 else 11
        full.update((left, right), k * 10_000)
        if k % 2 == 0 or k == 1:
            sparse.update((left, right), k * 10_000)
    # Curvature changes only at a sample both see, so every skipped interval is one exact arc.
    assert (sparse.pose.x_m, sparse.pose.y_m) == pytest.approx((full.pose.x_m, full.pose.y_m), abs=1e-9)
    assert sparse.pose.theta_rad == pytest.approx(full.pose.theta_rad, abs=1e-9)


def _feedback(counts: tuple[int, int], mcu_time_us: int) -> messages.Feedback:
    return messages.Feedback(
        1, mcu_time_us, 0, 0, 0, enums.Status.SESSION, enums.FailsafeReason.NONE, counts, (0, 0), (0, 0), 0
    )


def test_counts_and_time_wrapping_on_the_wire_keep_the_pose_continuous() -> None:
    """The session's tracker unwraps the wire's i32 counts and u32 time; odometry sees plain ints."""
    tracker, clock = FeedbackTracker(ROBOT), ClockSync()
    start = 2**31 - 100
    tracker.sample(_feedback((start, start), 2**32 - 50_000), 0.0, clock)
    wrapped = (start + 400 + 2**31) % 2**32 - 2**31  # 400 counts later, past the wrap
    sample = tracker.sample(_feedback((wrapped, wrapped), 50_000), 0.1, clock)
    assert sample.encoder_counts == (start + 400, start + 400)
    assert sample.mcu_time_us == 2**32 + 50_000
    pose = sample.pose
    assert pose is not None and pose.mcu_time_us == 2**32 + 50_000
    assert pose.x_m == pytest.approx(400 * ROBOT.metres_per_count)
    assert pose.linear_m_s == pytest.approx(400 * ROBOT.metres_per_count / 0.1)


class _MovingClock(ClockSync):
    """A clock sync whose fitted line the test sets (offset in seconds, host = mcu - offset)."""

    def __init__(self) -> None:
        super().__init__()
        self.offset_s: float | None = None

    @property
    def synced(self) -> bool:
        return self.offset_s is not None

    def host_s_of(self, mcu_us_unwrapped: int) -> float:
        assert self.offset_s is not None
        return mcu_us_unwrapped / 1e6 - self.offset_s


def test_sample_stamps_never_go_back_as_the_clock_fit_moves() -> None:
    """Stamped with the receive time until the first PONG, then with the fitted line (the board's
    sampling time, earlier than receipt), then a refit that moves the line 90 ms back: the stamps
    keep their order (tf2 and the ROS node's odometry drop or warn about stamps that go back)."""
    tracker, clock = FeedbackTracker(ROBOT), _MovingClock()
    stamps = []
    for i in range(12):
        if i == 3:
            clock.offset_s = 1.0 - 10.0 + 0.03  # the first PONG: sampling is 30 ms before receipt
        if i == 6:
            clock.offset_s += 0.09  # a refit moves the line back
        stamps.append(tracker.sample(_feedback((0, 0), 1_000_000 + 20_000 * i), 10.0 + 0.02 * i, clock).host_time_s)
    assert all(b > a for a, b in itertools.pairwise(stamps)), stamps
    assert stamps[4] == pytest.approx(10.08 - 0.03)  # the fitted line, where it does not go back
    assert stamps[11] == pytest.approx(10.22 - 0.12)  # and again once it has caught up


def test_turn_in_place_and_velocities() -> None:
    odo = Odometry(ROBOT)
    odo.update((0, 0), 0)
    quarter = ROBOT.track_m / 2 * (math.pi / 2) / ROBOT.metres_per_count
    pose = odo.update((-round(quarter), round(quarter)), 1_000_000)
    assert pose.theta_rad == pytest.approx(math.pi / 2, abs=2e-3)
    assert (pose.x_m, pose.y_m) == pytest.approx((0, 0), abs=1e-12)
    assert pose.angular_rad_s == pytest.approx(math.pi / 2, abs=2e-3)


def test_reset_sets_pose_and_reanchors() -> None:
    odo = Odometry(ROBOT)
    odo.update((0, 0), 0)
    odo.update((500, 500), 10_000)
    odo.reset(1.0, 2.0, 0.5)
    assert odo.update((9999, 9999), 20_000).x_m == 1.0  # first sample after reset: anchor only
    assert odo.update((9999 + 100, 9999 + 100), 30_000).x_m > 1.0


@given(st.floats(-1, 1), st.floats(-6, 6), st.floats(0.05, 2))
def test_wheel_speed_scaling_keeps_curvature(v: float, w: float, limit: float) -> None:
    left, right = ROBOT.wheel_speeds(v, w, limit)
    assert max(abs(left), abs(right)) <= limit + 1e-12
    lin, ang = ROBOT.twist(left, right)
    if abs(v) > 1e-6 and abs(lin) > 1e-9:
        assert ang / lin == pytest.approx(w / v, rel=1e-9, abs=1e-9)


def test_ackermann_turn_radius_and_limits() -> None:
    car = Ackermann(wheelbase_m=0.26, wheel_radius_m=0.0325, counts_per_rev=720, max_steering_rad=math.radians(25))
    steer = car.steering_for(1.0, 1.0)  # radius 1 m
    assert math.tan(steer) == pytest.approx(0.26)
    arc = car.arc(720, steer)
    assert arc.dtheta_rad == pytest.approx(arc.distance_m / 1.0)
    with pytest.raises(KinematicsError, match="minimum radius"):
        car.steering_for(1.0, 5.0)
    with pytest.raises(KinematicsError, match="turn in place"):
        car.steering_for(0.0, 1.0)
    with pytest.raises(ValueError, match="wheelbase_m = 0"):
        Ackermann(wheelbase_m=0, wheel_radius_m=0.03, counts_per_rev=100)
