"""The teleop obstacle guard against synthetic scans: whatever it lets through stops short of the
obstacles on its path (checked by walking the path, not with the corridor code the guard uses); it
slows as the way closes in, lets the robot move away from what it is too close to, stands without a
scan, and the override drives as asked. ENCODER_FAULT is explained, with what the lidar sees."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from host_sdk.autonomy.guard import GuardState, TeleopGuard, explain_failsafe, spin_angle, within_margin
from host_sdk.body import Footprint
from host_sdk.enums import FailsafeReason
from host_sdk.errors import FailsafeError
from host_sdk.failsafe import describe_failsafe
from host_sdk.perception.avoidance import AvoidanceParams, stopping_distance

DIFF = Footprint(0.12, 0.03)  # the TB6612 car's body
P = AvoidanceParams()
STEP_M = 0.002
TOLERANCE_M = 0.007
"""The guard lets a body already inside the margin come 5 mm nearer than it is; plus the walk's step."""


def gaps(x: np.ndarray, y: np.ndarray, fp: Footprint, pose: tuple[float, float, float]) -> np.ndarray:
    """Each point's gap to the footprint with the robot at `pose` (base frame of the start)."""
    px, py, th = pose
    cx, cy = px + fp.x_m * math.cos(th), py + fp.x_m * math.sin(th)
    return np.hypot(x - cx, y - cy) - fp.radius_m


def path(linear: float, angular: float, travel_m: float) -> list[tuple[float, float, float]]:
    """Poses along the arc the command drives, every STEP_M of travel up to `travel_m`."""
    k = angular / linear
    out = []
    for i in range(int(travel_m / STEP_M) + 2):
        s = math.copysign(min(i * STEP_M, travel_m), linear)
        th = s * k
        out.append((s, 0.0, 0.0) if abs(k) < 1e-9 else (math.sin(th) / k, (1 - math.cos(th)) / k, th))
    return out


def spin(turn_rad: float) -> list[tuple[float, float, float]]:
    n = max(2, int(abs(turn_rad) / 0.005))
    return [(0.0, 0.0, turn_rad * i / n) for i in range(n + 1)]


def closest_approach(
    x: np.ndarray, y: np.ndarray, fp: Footprint, poses: list[tuple[float, float, float]]
) -> np.ndarray:
    return np.min([gaps(x, y, fp, pose) for pose in poses], axis=0)


obstacles = st.lists(st.tuples(st.floats(-1.5, 1.5), st.floats(-1.5, 1.5)), min_size=1, max_size=25)


@settings(max_examples=400, deadline=None)
@given(
    points=obstacles,
    linear=st.floats(-0.6, 0.6),
    angular=st.floats(-2.5, 2.5),
    fp=st.builds(Footprint, st.floats(0.08, 0.25), st.floats(-0.1, 0.15)),
    car=st.booleans(),
)
def test_no_command_it_allows_reaches_into_the_margin_within_its_stopping_distance(
    points: list[tuple[float, float]], linear: float, angular: float, fp: Footprint, car: bool
) -> None:
    x, y = np.array([p[0] for p in points]), np.array([p[1] for p in points])
    now = gaps(x, y, fp, (0.0, 0.0, 0.0))
    x, y, now = x[now > 0.0], y[now > 0.0], now[now > 0.0]  # not inside the body (the bumper stops that)
    guard = TeleopGuard(fp, P, min_turn_radius_m=0.4 if car else 0.0)
    held = guard.limit(linear, angular, (x, y))
    v, w = held.linear_m_s, held.angular_rad_s
    assert held.state is not GuardState.OVERRIDE
    assert abs(v) <= abs(linear) + 1e-12 and (v == 0.0 or math.copysign(1, v) == math.copysign(1, linear))
    if abs(v) > 1e-9:  # (a speed of 1e-38 m/s is standing)
        assert w == pytest.approx(v * angular / linear)  # on the asked path, only slower
        poses = path(v, w, stopping_distance(v, P))
    elif w != 0.0 and not car:  # (a car's body twist with no speed drives nothing)
        assert w == angular  # a turn on the spot, as asked
        poses = spin(spin_angle(w, abs(fp.x_m) + fp.radius_m, P))
    else:
        return
    if x.size:  # the body keeps out of the margin, or, already in it, gets no deeper
        nearest = float(now.min())
        floor = (P.pad_m if nearest >= P.pad_m else nearest) - TOLERANCE_M
        assert float(closest_approach(x, y, fp, poses).min()) >= floor, held


def wall_ahead(d: float) -> tuple[np.ndarray, np.ndarray]:
    ys = np.linspace(-1.5, 1.5, 301)
    return np.full_like(ys, d), ys


def test_an_open_floor_lets_every_command_through() -> None:
    guard = TeleopGuard(DIFF)
    for v, w in ((0.27, 0.0), (0.27, 1.2), (-0.27, -0.8), (0.0, 1.2)):
        held = guard.limit(v, w, (np.zeros(0), np.zeros(0)))
        assert (held.linear_m_s, held.angular_rad_s, held.state) == (v, w, GuardState.CLEAR)
        assert not held.limited and held.obstacle is None


def test_it_slows_as_the_way_closes_in_and_stops_short_of_the_wall() -> None:
    guard = TeleopGuard(DIFF)
    speeds = [guard.limit(0.27, 0.0, wall_ahead(d)).linear_m_s for d in (2.0, 0.8, 0.6, 0.5, 0.4, 0.35)]
    assert speeds[:2] == [0.27, 0.27] and speeds == sorted(speeds, reverse=True) and 0 < speeds[-1] < 0.1
    stopped = guard.limit(0.27, 0.0, wall_ahead(0.28))
    assert stopped.state is GuardState.STOPPED and stopped.linear_m_s == 0.0
    assert stopped.obstacle is not None and stopped.obstacle.side == "ahead"
    assert stopped.obstacle.range_m == pytest.approx(0.28, abs=0.01)
    assert "stopped for an obstacle 0.13 m ahead of the body" in stopped.text and "override" in stopped.text
    curving = guard.limit(0.27, 0.3, wall_ahead(0.5))  # slowed on the arc asked: the turn slows with it
    assert curving.state is GuardState.SLOWED and curving.linear_m_s < 0.27
    assert curving.angular_rad_s / curving.linear_m_s == pytest.approx(0.3 / 0.27)


def test_it_lets_the_robot_back_and_turn_away_from_what_it_is_too_close_to() -> None:
    guard = TeleopGuard(DIFF)
    touching = wall_ahead(DIFF.x_m + DIFF.radius_m + 0.01)  # 1 cm off the bumper
    assert guard.limit(0.27, 0.0, touching).linear_m_s == 0.0
    assert guard.limit(-0.27, 0.0, touching).linear_m_s == -0.27  # backing away
    assert guard.limit(0.0, 1.2, touching).angular_rad_s == 1.2  # the body turns nearly in its own place
    forward_left = guard.limit(0.27, 1.2, touching)  # no room on the arc: the turn on the spot is left
    assert (forward_left.linear_m_s, forward_left.angular_rad_s) == (0.0, 1.2)
    behind = wall_ahead(-0.2)  # 11 cm behind the body
    assert guard.limit(-0.27, 0.0, behind).linear_m_s == 0.0  # and backing into something is not allowed
    car = TeleopGuard(Footprint(0.19, 0.13), min_turn_radius_m=0.37)
    assert car.limit(0.2, 0.5, wall_ahead(0.33)).angular_rad_s == 0.0  # a car cannot turn standing


def test_a_body_ahead_of_its_pose_point_may_not_swing_into_a_post_beside_it() -> None:
    fp = Footprint(0.15, 0.15)
    post = (np.array([0.12]), np.array([0.2]))  # ahead on the left, 3 cm from the body
    guard = TeleopGuard(fp)
    assert guard.limit(0.0, 1.2, post).state is GuardState.STOPPED  # turning left swings the nose into it
    assert guard.limit(0.0, -1.2, post).angular_rad_s == -1.2  # turning right swings it away


def test_without_a_recent_scan_it_stands_and_the_override_drives_as_asked() -> None:
    guard = TeleopGuard(DIFF)
    blind = guard.limit(0.27, 0.0, None)
    assert (blind.linear_m_s, blind.angular_rad_s, blind.state) == (0.0, 0.0, GuardState.NO_SCAN) and blind.limited
    old = guard.limit(0.27, 0.0, wall_ahead(3.0), age_s=1.5)
    assert old.state is GuardState.NO_SCAN and "1.5 s" in old.text
    over = guard.limit(0.27, 0.0, wall_ahead(0.25), override=True)
    assert (over.linear_m_s, over.state) == (0.27, GuardState.OVERRIDE) and not over.limited
    assert over.obstacle is not None and "override held" in over.text and "0.10 m ahead of the body" in over.text
    assert guard.limit(0.27, 0.0, None, override=True).linear_m_s == 0.27


def test_encoder_fault_reads_as_a_blocked_wheel_or_an_unplugged_encoder() -> None:
    words = "a wheel did not turn under effort: blocked, or its encoder unplugged"
    assert describe_failsafe(FailsafeReason.ENCODER_FAULT) == f"ENCODER_FAULT: {words}"
    assert words in str(FailsafeError(FailsafeReason.ENCODER_FAULT, words))
    bump = (np.array([0.17, 1.0]), np.array([0.01, 0.5]))  # 2 cm off the bumper, dead ahead
    near = within_margin(bump, DIFF, P.margin_m)
    assert near is not None and near.side == "ahead"
    text = explain_failsafe(FailsafeReason.ENCODER_FAULT, near, P.margin_m)
    assert text.startswith(f"ENCODER_FAULT: {words}; ")
    assert "the lidar sees an obstacle 0.02 m ahead of the body, inside the footprint's 0.08 m margin" in text
    clear = within_margin((np.array([0.5]), np.array([0.0])), DIFF, P.margin_m)
    assert clear is None and explain_failsafe(FailsafeReason.ENCODER_FAULT, clear, P.margin_m) == describe_failsafe(
        FailsafeReason.ENCODER_FAULT
    )
