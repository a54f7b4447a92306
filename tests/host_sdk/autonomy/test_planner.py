"""The view planner with known geometry: a car (the PiCar's footprint, camera and steering arcs)
driven by the planner's choices in a small kinematic loop, in scenes where the right move is known."""

from __future__ import annotations

import math

import numpy as np
import pytest

from host_sdk.autonomy import PlanChoice, PlannerParams, ViewPlanner
from host_sdk.perception import CameraModel, Footprint

CAM = CameraModel.pi_camera_v2(320, 240, mount_x_m=0.3)
PICAR = Footprint(0.19, 0.13)
ARCS = (-1.794, -1.031, 0.0, 1.031, 2.221)
"""The PiCar's steering reaches -25, -15, 0, 15 and 30 degrees (wheelbase 0.26 m)."""
GAP = 0.9
R = 0.12


def planner(**params: float) -> ViewPlanner:
    return ViewPlanner(PICAR, CAM, curvatures=ARCS, params=PlannerParams(**params))  # type: ignore[arg-type]


def to_base(pose: tuple[float, float, float], x: float, y: float) -> tuple[float, float]:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return c * (x - pose[0]) + s * (y - pose[1]), -s * (x - pose[0]) + c * (y - pose[1])


def surface(pose: tuple[float, float, float], cx: float, cy: float) -> tuple[float, float]:
    """The target's near surface point in the base frame, for a target centred at (cx, cy)."""
    bx, by = to_base(pose, cx, cy)
    d = math.hypot(bx, by)
    return bx - R * bx / d, by - R * by / d


def off_axis(pose: tuple[float, float, float], cx: float, cy: float) -> float:
    bx, by = to_base(pose, cx, cy)
    return abs(math.atan2(by, bx - CAM.mount_x_m)) / CAM.half_fov_rad


def drive(
    pl: ViewPlanner,
    pose: tuple[float, float, float],
    obstacles: tuple[np.ndarray, np.ndarray],
    target: tuple[float, float],
    *,
    velocity: tuple[float, float] = (0.0, 0.0),
    seconds: float = 4.0,
) -> list[tuple[float, float, float, float, float]]:
    """Closed loop at 20 Hz: the planner's command moves the car exactly (no latency); the target
    moves at `velocity` (world frame). Returns (x, y, heading, target x, target y) per step."""
    wx, wy = obstacles
    tx, ty = target
    last = (0.0, 0.0)
    out = []
    for _ in range(round(seconds / 0.05)):
        x, y, th = pose
        c, s = math.cos(th), math.sin(th)
        ox, oy = c * (wx - x) + s * (wy - y), -s * (wx - x) + c * (wy - y)
        vb = (c * velocity[0] + s * velocity[1], -s * velocity[0] + c * velocity[1])
        choice = pl.plan(ox, oy, target=surface(pose, tx, ty), target_velocity=vb, gap_m=GAP, last=last)
        v, w = choice.linear_m_s, choice.angular_rad_s
        last = (v, w)
        pose = (x + 0.05 * v * math.cos(th + 0.025 * w), y + 0.05 * v * math.sin(th + 0.025 * w), th + 0.05 * w)
        tx, ty = tx + 0.05 * velocity[0], ty + 0.05 * velocity[1]
        out.append((*pose, tx, ty))
    return out


def room(w: float = 6.0, h: float = 6.0, cx: float = 0.0, cy: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The walls of a room centred at (cx, cy), a point every 3 cm."""
    xs, ys = [], []
    for x0, y0, x1, y1 in ((-1, -1, 1, -1), (1, -1, 1, 1), (1, 1, -1, 1), (-1, 1, -1, -1)):
        n = int(max(abs(x1 - x0) * w, abs(y1 - y0) * h) / 2 / 0.03)
        xs.append(cx + np.linspace(x0, x1, n) * w / 2)
        ys.append(cy + np.linspace(y0, y1, n) * h / 2)
    return np.concatenate(xs), np.concatenate(ys)


def box(cx: float, cy: float, half: float) -> tuple[np.ndarray, np.ndarray]:
    s = np.linspace(-half, half, max(2, int(2 * half / 0.03)))
    e = np.full_like(s, half)
    return np.concatenate([cx + s, cx + e, cx + s, cx - e]), np.concatenate([cy - e, cy + s, cy + e, cy + s])


def join(*parts: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def clearance(run: list[tuple[float, float, float, float, float]], obstacles: tuple[np.ndarray, np.ndarray]) -> float:
    wx, wy = obstacles
    return (
        min(
            float(np.hypot(wx - (x + PICAR.x_m * math.cos(th)), wy - (y + PICAR.x_m * math.sin(th))).min())
            for x, y, th, _, _ in run
        )
        - PICAR.radius_m
    )


def test_a_target_standing_ahead_at_the_gap_is_stood_at() -> None:
    pl = planner()
    run = drive(pl, (0.0, 0.0, 0.0), room(), (0.13 + 0.19 + GAP + R, 0.0), seconds=2.0)
    x, y, th, _, _ = run[-1]
    assert math.hypot(x, y) < 0.1 and abs(th) < 0.1


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_a_target_beside_the_car_is_brought_into_the_picture(side: float) -> None:
    """60 degrees off the camera's axis, at the gap: out of the picture. A car cannot turn on the
    spot; it has to drive (back and forth) to swing the camera round, and it does, on either side,
    although its steering reaches further to the left than to the right."""
    target = (0.9, side * 1.0)
    assert off_axis((0.0, 0.0, 0.0), *target) > 1.5
    run = drive(planner(), (0.0, 0.0, 0.0), room(), target, seconds=4.0)
    assert off_axis(run[-1][:3], *target) < 0.6
    assert clearance(run, room()) > 0.0


def test_a_target_behind_the_car_is_turned_round_to() -> None:
    target = (-1.5, 0.3)
    run = drive(planner(), (0.0, 0.0, 0.0), room(), target, seconds=8.0)
    inside = [off_axis((x, y, th), *target) < 1.0 for x, y, th, _, _ in run]
    assert any(inside[:100]), "turned round within 5 s"
    assert all(inside[-20:])


def test_a_wall_ahead_is_never_driven_into() -> None:
    """The target stands beyond a wall the car faces: the car may move, but never into the wall."""
    walls = join(room(), (np.full(60, 0.6), np.linspace(-0.9, 0.9, 60)))
    run = drive(planner(), (0.0, 0.0, 0.0), walls, (2.0, 0.0), seconds=4.0)
    assert clearance(run, walls) >= 0.03


def test_a_target_walking_at_the_car_is_got_out_of_the_way_of() -> None:
    """It walks straight at the car's nose (the target does not avoid the robot); standing there,
    the car would be hit within 3 s. The planner moves it out of the way."""
    target, velocity = (1.4, 0.0), (-0.3, 0.0)
    pl = planner()
    run = drive(pl, (0.0, 0.0, 0.0), room(8, 8), target, velocity=velocity, seconds=5.0)
    for x, y, th, tx, ty in run:
        fx, fy = x + PICAR.x_m * math.cos(th), y + PICAR.x_m * math.sin(th)
        assert math.hypot(tx - fx, ty - fy) - PICAR.radius_m - R > 0.05


def test_a_box_hiding_the_target_is_looked_past() -> None:
    """A box stands between the camera and the target: in the field of view, not in sight. The car
    moves until it sees the target past the box."""
    walls = join(room(), box(1.1, 0.12, 0.1))
    target = (2.4, 0.0)

    def in_sight(pose: tuple[float, float, float]) -> bool:
        x, y, th = pose
        camx, camy = x + CAM.mount_x_m * math.cos(th), y + CAM.mount_x_m * math.sin(th)
        t = np.linspace(0.05, 0.85, 40)
        px, py = camx + t * (target[0] - camx), camy + t * (target[1] - camy)
        d = np.hypot(px[:, None] - walls[0][None, :], py[:, None] - walls[1][None, :]).min()
        return bool(d > 0.03) and off_axis(pose, *target) < 1.0

    assert not in_sight((0.0, 0.0, 0.0))
    run = drive(planner(), (0.0, 0.0, 0.0), walls, target, seconds=5.0)
    assert in_sight(run[-1][:3])
    assert clearance(run, walls) > 0.0


def test_the_arcs_planned_are_the_arcs_the_steering_reaches() -> None:
    pl = planner()
    for target in ((1.0, 0.8), (1.0, -0.8), (-1.0, 0.5), (2.0, 0.0)):
        c = pl.plan(*room(), target=target, target_velocity=(0.0, 0.0), gap_m=GAP)
        if c.linear_m_s != 0.0:
            assert min(abs(c.angular_rad_s / c.linear_m_s - k) for k in ARCS) < 1e-9


def test_boxed_in_it_stands() -> None:
    a = np.linspace(-math.pi, math.pi, 180, endpoint=False)
    ring = (0.13 + 0.23 * np.cos(a), 0.23 * np.sin(a))
    c = planner().plan(*ring, target=(1.5, 0.5), target_velocity=(0.0, 0.0), gap_m=GAP)
    assert (c.linear_m_s, c.angular_rad_s) == (0.0, 0.0)


def test_the_way_the_car_began_to_move_is_held_unless_that_runs_into_the_target() -> None:
    """Standing closer than the follow gap, the target is best backed away from; asked to hold
    forwards, the planner keeps to forwards or standing, and the other way round. A target walking
    at the car breaks the hold: holding to forwards would run into it."""
    pl = planner()
    free = pl.plan(*room(8, 8), target=(0.5, 0.0), target_velocity=(0.0, 0.0), gap_m=GAP)
    assert free.linear_m_s < 0
    held = pl.plan(*room(8, 8), target=(0.5, 0.0), target_velocity=(0.0, 0.0), gap_m=GAP, direction=1.0)
    assert held.linear_m_s >= 0 and held.min_separation_m > 0
    back = pl.plan(*room(8, 8), target=(2.5, 0.0), target_velocity=(0.0, 0.0), gap_m=GAP, direction=-1.0)
    assert back.linear_m_s <= 0
    coming = pl.plan(*room(8, 8), target=(0.6, 0.0), target_velocity=(-0.3, 0.0), gap_m=GAP, direction=1.0)
    assert coming.linear_m_s < 0


def test_having_just_started_it_keeps_going_unless_that_runs_into_the_target() -> None:
    """The target stands at the follow gap, where standing is best. Just started forwards
    (`moving`), the car keeps going for a moment (replanning between standing and going 20 times a
    second, a car never got moving); not when going on would run into a target coming at it."""
    pl = planner()
    at_gap = (PICAR.x_m + PICAR.radius_m + GAP, 0.0)
    still = pl.plan(*room(8, 8), target=at_gap, target_velocity=(0.0, 0.0), gap_m=GAP, last=(0.2, 0.0))
    assert still.linear_m_s == 0.0
    going = pl.plan(
        *room(8, 8), target=at_gap, target_velocity=(0.0, 0.0), gap_m=GAP, last=(0.2, 0.0), direction=1.0, moving=True
    )
    assert going.linear_m_s > 0.0 and going.min_separation_m > 0.0
    coming = pl.plan(
        *room(8, 8),
        target=(0.8, 0.0),
        target_velocity=(-0.3, 0.0),
        gap_m=GAP,
        last=(0.2, 0.0),
        direction=1.0,
        moving=True,
    )
    assert coming.linear_m_s < 0.0


def test_a_target_walking_its_route_again_is_predicted_to_turn_where_it_turned() -> None:
    """Round a 2 m square once (seen every 0.1 s); on its second lap, half a metre before a corner,
    the prediction turns the corner with it, where its velocity alone would run straight on. Before
    it has walked the route once, there is nothing to go by but its velocity."""
    from host_sdk.autonomy.memory import TargetMemory
    from host_sdk.autonomy.target import TargetFix

    corners = [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0), (0.0, 0.0)]

    def at(s: float) -> tuple[float, float]:
        s %= 8.0
        k = int(s // 2.0)
        (ax, ay), (bx, by) = corners[k], corners[k + 1]
        f = (s - 2.0 * k) / 2.0
        return ax + f * (bx - ax), ay + f * (by - ay)

    memory = TargetMemory(0.3)
    none = np.zeros(0, dtype=bool)
    pose = (1.0, 1.0, 0.0)  # the robot stands in the middle (the odometry frame is the base frame moved)
    times = np.arange(1, 17) * 0.2
    for i in range(36):  # 0.25 m/s: 0.9 m of its first lap
        t = 0.1 * i
        x, y = at(0.25 * t)
        memory.remember(t, TargetFix(x - 1.0, y - 1.0, none, True), pose)
    assert memory.ahead(3.5, pose, times) is None
    for i in range(36, 381):
        t = 0.1 * i
        x, y = at(0.25 * t)
        memory.remember(t, TargetFix(x - 1.0, y - 1.0, none, True), pose)
    # Now at 0.25 * 38 = 9.5 m: 1.5 m along the first side, 0.5 m from the corner at (2, 0).
    path = memory.ahead(38.0, pose, times)
    assert path is not None
    px, py = path
    truth = np.array([at(0.25 * (38.0 + float(tt))) for tt in times]) - 1.0
    assert np.hypot(px - truth[:, 0], py - truth[:, 1]).max() < 0.1
    assert py[-1] > -0.8  # round the corner (straight on, it would still be at y = -1)


def test_the_path_the_target_is_predicted_on_is_what_is_planned_for() -> None:
    """1.7 m ahead, walking across: by its velocity the car closes in; told that it turns towards
    the car and comes at 0.45 m/s (its route does), the car does not drive at it."""
    pl = planner()
    across = pl.plan(*room(8, 8), target=(1.7, 0.3), target_velocity=(0.0, -0.25), gap_m=GAP)
    assert across.linear_m_s > 0.0
    t = pl.path_times
    turning = (1.7 - 0.45 * np.maximum(t - 0.4, 0.0), 0.3 - 0.25 * np.minimum(t, 0.4))
    coming = pl.plan(*room(8, 8), target=(1.7, 0.3), target_velocity=(0.0, -0.25), gap_m=GAP, target_path=turning)
    assert coming.linear_m_s <= 0.0 and coming.min_separation_m > 0.5


def test_a_car_does_not_stop_where_the_target_walks_into_it_after_the_horizon() -> None:
    """Coming straight at the car, 1.45 m off, at 0.25 m/s: inside the horizon it stays clear, so
    standing looks fine, but it walks into the car 1 to 2 s later, with a box behind the car. Looking
    past the horizon, the car ends its manoeuvre off the target's line; without, it stays on it."""
    obstacles = join(room(), box(-0.45, 0.0, 0.15))

    def come(pl: ViewPlanner) -> PlanChoice:
        return pl.plan(*obstacles, target=(1.45, 0.0), target_velocity=(-0.25, 0.0), gap_m=0.5)

    blind = come(planner(w_late=0.0))
    assert blind.min_separation_m > 0.0 and blind.late_separation_m < 0.0
    seeing = come(planner())
    assert seeing.min_separation_m > 0.0 and seeing.late_separation_m >= 0.0
    assert abs(seeing.path_xy[-1][1]) > 0.2


def test_only_a_car_looks_past_the_horizon() -> None:
    """A differential drive steps aside on the spot: its planner wants the target's path over the
    horizon only."""
    car = planner()
    assert car.path_times.size == car.times.size + round(car.params.late_s / car.params.step_s)
    drive = ViewPlanner(PICAR, CAM, turn_rates=(-2.0, 2.0))
    np.testing.assert_array_equal(drive.path_times, drive.times)
    choice = drive.plan(*room(), target=(1.45, 0.0), target_velocity=(-0.25, 0.0), gap_m=0.5)
    assert choice.late_separation_m == math.inf
