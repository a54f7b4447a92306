"""Obstacle avoidance with known geometry: the swept corridor against brute force, clear directions,
the Ackermann mask, the speed law, and the planner's choices."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from host_sdk.perception.avoidance import (
    AvoidanceParams,
    Avoider,
    Footprint,
    ackermann_mask,
    arc_free_distance,
    direction_clearance,
    safe_speed,
    stopping_distance,
)

DISC = Footprint(radius_m=0.2)


def brute_force(px: float, py: float, k: float, fp: Footprint, horizon: float, *, reverse: bool = False) -> float:
    """Step the pose point along the arc 1 mm at a time until the footprint touches the point."""
    sign = -1.0 if reverse else 1.0
    for i in range(int(horizon / 0.001) + 1):
        s = sign * i * 0.001
        th = s * k
        if abs(k) < 1e-9:
            x, y = s, 0.0
        else:
            x, y = math.sin(th) / k, (1 - math.cos(th)) / k
        cx, cy = x + fp.x_m * math.cos(th), y + fp.x_m * math.sin(th)
        if math.hypot(px - cx, py - cy) < fp.radius_m:
            return i * 0.001
    return horizon


def test_straight_corridor() -> None:
    d = arc_free_distance(np.array([2.0, 2.0, 2.0]), np.array([0.0, 0.1, 0.3]), np.array([0.0]), DISC)
    assert d[0] == pytest.approx(1.8)  # the point dead ahead is the first touched
    d = arc_free_distance(np.array([2.0]), np.array([0.1]), np.array([0.0]), DISC)
    assert d[0] == pytest.approx(2 - math.sqrt(0.04 - 0.01))
    # A point beside the corridor is never touched: the horizon comes back.
    assert arc_free_distance(np.array([2.0]), np.array([0.3]), np.array([0.0]), DISC, horizon_m=4)[0] == 4


def test_a_quarter_turn_left() -> None:
    # Turning left on a 1 m circle, a point on that circle a quarter turn ahead, footprint radius 0.2.
    d = arc_free_distance(np.array([1.0]), np.array([1.0]), np.array([1.0]), DISC)[0]
    assert d == pytest.approx(math.pi / 2 - math.acos(0.98), abs=1e-9)


def test_reversing_and_an_offset_footprint() -> None:
    fp = Footprint(radius_m=0.2, x_m=0.1)
    d = arc_free_distance(np.array([-1.0]), np.array([0.0]), np.array([0.0]), fp, reverse=True)[0]
    assert d == pytest.approx(0.9)
    assert arc_free_distance(np.array([0.25]), np.array([0.0]), np.array([0.0]), fp)[0] == 0.0  # touching now


@given(
    px=st.floats(-2, 2),
    py=st.floats(-2, 2),
    k=st.floats(-3, 3),
    fx=st.floats(-0.1, 0.2),
    reverse=st.booleans(),
)
def test_swept_corridor_matches_brute_force(px: float, py: float, k: float, fx: float, reverse: bool) -> None:
    fp = Footprint(radius_m=0.15, x_m=fx)
    got = arc_free_distance(np.array([px]), np.array([py]), np.array([k]), fp, horizon_m=3.0, reverse=reverse)[0]
    assert got == pytest.approx(brute_force(px, py, k, fp, 3.0, reverse=reverse), abs=0.003)


def test_direction_clearance_of_a_wall_ahead() -> None:
    ys = np.linspace(-2, 2, 401)
    xs = np.full_like(ys, 1.0)
    dirs = np.radians([0.0, 30.0, 90.0, 180.0])
    clear = direction_clearance(xs, ys, dirs, 0.25, horizon_m=5.0)
    assert clear[0] == pytest.approx(0.75, abs=0.01)
    assert clear[1] == pytest.approx(0.75 / math.cos(math.radians(30)), abs=0.01)  # a disc 0.25 wide meets x = 1
    assert clear[2] == 5.0 and clear[3] == 5.0


def test_ackermann_mask_blocks_turns_into_an_obstacle_inside_the_turning_circle() -> None:
    dirs = np.radians(np.arange(-180, 180, 10.0))
    ok = ackermann_mask(np.array([0.2]), np.array([0.4]), dirs, 0.37, 0.2)
    bearing = math.degrees(math.atan2(0.4, 0.2))
    degrees = np.degrees(dirs)
    assert ok[degrees < bearing].all()
    assert not ok[degrees > bearing].any()
    # A differential-drive robot (radius 0) has no mask; an obstacle far away masks nothing.
    assert ackermann_mask(np.array([0.2]), np.array([0.4]), dirs, 0.0, 0.2).all()
    assert ackermann_mask(np.array([3.0]), np.array([0.4]), dirs, 0.37, 0.2).all()


@pytest.mark.parametrize("free", [0.1, 0.5, 1.0, 3.0])
def test_safe_speed_stops_within_the_free_distance(free: float) -> None:
    p = AvoidanceParams()
    v = safe_speed(free, p, ttc=False)
    assert stopping_distance(v, p) == pytest.approx(free)
    assert safe_speed(free, p) <= v
    assert safe_speed(free, p) == pytest.approx(min(v, (free - p.stop_margin_m) / p.min_ttc_s))
    assert safe_speed(p.stop_margin_m, p) == 0.0


def wall(x0: float, y0: float, x1: float, y1: float, n: int = 60) -> tuple[np.ndarray, np.ndarray]:
    return np.linspace(x0, x1, n), np.linspace(y0, y1, n)


def test_planner_goes_straight_when_the_way_is_clear() -> None:
    plan = Avoider(DISC).plan(np.array([]), np.array([]), 0.0, 0.5)
    assert plan.speed_m_s == 0.5 and plan.curvature == 0.0 and not plan.deflected and not plan.blocked


def test_planner_deflects_round_a_box_towards_the_open_side() -> None:
    bx, by = wall(1.0, -0.3, 1.0, 0.3)  # a box face ahead
    rx, ry = wall(0.0, -0.6, 2.5, -0.6)  # a wall on the right
    px, py = np.concatenate([bx, rx]), np.concatenate([by, ry])
    plan = Avoider(DISC).plan(px, py, 0.0, 0.5)
    assert plan.deflected and plan.direction_rad > 0 and plan.curvature > 0
    assert plan.free_m > stopping_distance(plan.speed_m_s, AvoidanceParams())


def test_planner_slows_down_as_the_way_closes_in() -> None:
    avoider = Avoider(DISC, AvoidanceParams(max_curvature=0.01))  # no turning away: straight at the wall
    speeds = []
    for d in (3.0, 1.5, 1.0, 0.6, 0.35):
        x, y = wall(d, -3, d, 3, 200)
        speeds.append(avoider.plan(x, y, 0.0, 1.0).speed_m_s)
    assert speeds == sorted(speeds, reverse=True) and speeds[-1] < 0.15


def test_boxed_in_is_blocked() -> None:
    a = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    plan = Avoider(DISC).plan(0.35 * np.cos(a), 0.35 * np.sin(a), 0.0, 0.5)
    assert plan.blocked and plan.speed_m_s == 0.0


def test_the_target_does_not_repel_but_still_bounds_the_speed() -> None:
    """The case the PiCar could not handle: the followed target straight ahead, closer than 1.3 m.
    With its points passed as the target, the plan keeps heading at it, slower as it gets close."""
    a = np.linspace(-0.2, 0.2, 15)
    tx, ty = 0.9 + 0.12 * np.cos(a + math.pi), 0.12 * np.sin(a + math.pi)
    avoider = Avoider(DISC)
    as_obstacle = avoider.plan(tx, ty, 0.0, 0.4)
    assert as_obstacle.deflected  # seen as an obstacle, it pushes the robot aside
    as_target = Avoider(DISC).plan(np.array([]), np.array([]), 0.0, 0.4, target_xy=(tx, ty))
    assert not as_target.deflected and as_target.direction_rad == 0.0 and 0 < as_target.speed_m_s <= 0.4
    near = Avoider(DISC).plan(np.array([]), np.array([]), 0.0, 0.4, target_xy=(tx - 0.5, ty))
    assert near.speed_m_s < as_target.speed_m_s


def test_ackermann_planner_respects_its_turning_radius() -> None:
    params = AvoidanceParams(min_turn_radius_m=0.5)
    avoider = Avoider(DISC, params)
    assert avoider.params.max_curvature == pytest.approx(2.0)
    plan = avoider.plan(np.array([]), np.array([]), math.radians(120), 0.3)
    assert plan.curvature == pytest.approx(2.0)  # as tight as it can, never tighter
    # Something inside the left turning circle: left is masked, the planner turns right instead.
    bx, by = wall(0.3, 0.35, 0.6, 0.6, 20)
    fx, fy = wall(0.9, -0.4, 0.9, 0.9, 60)
    plan = avoider.plan(np.concatenate([bx, fx]), np.concatenate([by, fy]), math.radians(60), 0.3)
    assert plan.direction_rad < 0


def test_arc_room_keeps_a_margin_but_lets_a_robot_that_is_too_close_move_away() -> None:
    from host_sdk.perception.avoidance import arc_room

    wall_x, wall_y = wall(1.0, -2.0, 1.0, 2.0, 200)
    bare = arc_free_distance(wall_x, wall_y, np.array([0.0]), DISC)[0]
    padded = arc_room(wall_x, wall_y, np.array([0.0]), DISC, pad_m=0.05)[0]
    assert padded == pytest.approx(bare - 0.05, abs=0.002)
    # A point 2 cm off the footprint (inside the margin), ahead on the left: backing away is free,
    # driving on past it is not (without the margin it would be: the bare disc just clears it).
    x, y = np.array([0.1]), np.array([0.2])
    away = arc_room(x, y, np.array([0.0]), DISC, pad_m=0.05, horizon_m=2.0, reverse=True)[0]
    towards = arc_room(x, y, np.array([0.0]), DISC, pad_m=0.05, horizon_m=2.0)[0]
    assert away == 2.0 and towards < 0.11
    assert arc_free_distance(x, y, np.array([-1.0]), DISC, horizon_m=2.0)[0] == 2.0
