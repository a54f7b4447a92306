"""What moves in the scan, with known geometry: a walker crossing a room is found where it is; a
robot driving past boxes sees nothing move; revolutions taken while turning fast are not compared."""

from __future__ import annotations

import math

import numpy as np

from host_sdk.autonomy import Follower
from host_sdk.autonomy.follow_params import Mode
from host_sdk.perception import CameraModel, Footprint, MotionDetector, ObstacleScan
from host_sdk.perception.scan import bin_points, move_points

BINS = 360
ANGLES = -math.pi + (np.arange(BINS) + 0.5) * 2 * math.pi / BINS
RATE_HZ = 5.5


def room(walker: tuple[float, float] | None) -> tuple[np.ndarray, np.ndarray]:
    """World points: a 5 x 4 m room, 0.4 m boxes at (1.0, 1.0) and (-1.8, 1.4), and a 0.3 m walker."""
    s = np.arange(0.0, 1.0, 0.002)
    xs = [np.concatenate([-2.5 + 5 * s, -2.5 + 5 * s, np.full_like(s, -2.5), np.full_like(s, 2.5)])]
    ys = [np.concatenate([np.full_like(s, -2.0), np.full_like(s, 2.0), -2 + 4 * s, -2 + 4 * s])]
    for bx, by in ((1.0, 1.0), (-1.8, 1.4)):
        xs.append(
            np.concatenate(
                [bx - 0.2 + 0.4 * s, bx - 0.2 + 0.4 * s, np.full_like(s, bx - 0.2), np.full_like(s, bx + 0.2)]
            )
        )
        ys.append(
            np.concatenate(
                [np.full_like(s, by - 0.2), np.full_like(s, by + 0.2), by - 0.2 + 0.4 * s, by - 0.2 + 0.4 * s]
            )
        )
    if walker is not None:
        a = 2 * math.pi * s
        xs.append(walker[0] + 0.15 * np.cos(a))
        ys.append(walker[1] + 0.15 * np.sin(a))
    return np.concatenate(xs), np.concatenate(ys)


def revolution(t: float, pose: tuple[float, float, float], walker: tuple[float, float] | None) -> ObstacleScan:
    """The nearest return per degree seen from `pose` (occlusion by binning: nearest wins)."""
    wx, wy = room(walker)
    x, y = move_points(wx, wy, (0.0, 0.0, 0.0), pose)
    return ObstacleScan(ANGLES, bin_points(x, y, BINS), t)


def run(pose_at, walker_at, seconds: float = 6.0):  # type: ignore[no-untyped-def]
    det = MotionDetector()
    found = []
    for i in range(int(seconds * RATE_HZ)):
        t = i / RATE_HZ
        found.append((t, det.update(revolution(t, pose_at(t), walker_at(t)), pose_at(t))))
    return found


def test_a_walker_crossing_the_room_is_found_where_it_is() -> None:
    def walker(t: float) -> tuple[float, float]:
        return (-1.5 + 0.2 * t, -1.0)

    found = run(lambda t: (0.0, 0.0, 0.0), walker)
    later = [(t, m) for t, m in found if t > 3.0]
    assert all(len(m) == 1 for _, m in later), later  # the walker, and nothing else
    for t, (mover,) in later:
        wx, wy = walker(t)
        assert math.hypot(mover.x_m - wx, mover.y_m - wy) < 0.2  # a point of its surface
        assert mover.hits >= 2


def test_driving_and_turning_slowly_past_still_things_shows_nothing_moving() -> None:
    def pose(t: float) -> tuple[float, float, float]:
        return (-1.5 + 0.3 * t, -0.5 + 0.05 * t, 0.2 * t)

    found = run(pose, lambda t: None)
    assert all(m == () for _, m in found)


def turning(rate: float, walker_at, seconds: float = 6.0, glitch_rad: float = 0.0):  # type: ignore[no-untyped-def]
    """Revolutions taken while turning at `rate` (rad/s) as a spinning lidar takes them: each
    30-degree sector of a revolution at the heading the robot had when the beam swept it; the
    detector is given the heading at mid-revolution (every fifth one `glitch_rad` off)."""
    det = MotionDetector()
    found = []
    sectors = 12
    for i in range(int(seconds * RATE_HZ)):
        t = i / RATE_HZ
        ranges = np.full(BINS, np.nan)
        for j in range(sectors):
            heading = rate * (t + ((j + 0.5) / sectors - 0.5) / RATE_HZ)
            part = revolution(t, (0.0, 0.0, heading), walker_at(t)).ranges_m
            lo, hi = j * BINS // sectors, (j + 1) * BINS // sectors
            ranges[lo:hi] = part[lo:hi]
        heading = rate * t + (glitch_rad if i % 5 == 4 else 0.0)
        found.append((t, det.update(ObstacleScan(ANGLES, ranges, t), (0.0, 0.0, heading))))
    return found


def test_spinning_shows_nothing_moving() -> None:
    # At 1.5 rad/s revolutions are not compared at all; box edges and the standing walker would
    # otherwise "move" by the skew of every revolution.
    assert all(m == () for _, m in turning(1.5, lambda t: (-1.0, -1.0)))


def test_turning_slowly_a_walker_is_found_and_a_standing_one_is_not() -> None:
    # An Ackermann robot searching by K-turns turns at about 0.7 rad/s: the beams compared are
    # widened by the turn during a revolution, so skewed edges do not move and the walker does.
    assert all(m == () for _, m in turning(0.7, lambda t: (-1.0, -1.0)))

    def walker(t: float) -> tuple[float, float]:
        return (-1.5 + 0.2 * t, -1.0)

    later = [(t, m) for t, m in turning(0.7, walker) if t > 3.0]
    # Widened beams see less: found in some revolutions (enough to turn to it), never elsewhere.
    assert sum(len(m) == 1 for _, m in later) >= len(later) // 4, later
    for t, movers in later:
        for mover in movers:
            assert math.hypot(mover.x_m - walker(t)[0], mover.y_m - walker(t)[1]) < 0.3


def test_one_revolution_with_a_poor_pose_does_not_blind_it() -> None:
    # A revolution's pose comes from the host's loop: now and then one is a control step or two off
    # (0.15 rad here), and that revolution's own turn looks twice as fast as the robot turns. The
    # turn rate is judged over half a second, so a robot turning at 0.6 rad/s is not taken for a
    # spinning one (which would forget every revolution and see nothing move for seconds).
    def walker(t: float) -> tuple[float, float]:
        return (-1.5 + 0.2 * t, -1.0)

    later = [(t, m) for t, m in turning(0.6, walker, glitch_rad=0.15) if t > 3.0]
    assert sum(len(m) == 1 for _, m in later) >= len(later) // 2, later
    for t, movers in later:
        for mover in movers:
            assert math.hypot(mover.x_m - walker(t)[0], mover.y_m - walker(t)[1]) < 0.3


def test_a_lost_target_is_looked_for_where_something_moves() -> None:
    follower = Follower(Footprint(0.15, 0.0), CameraModel.pi_camera_v2(320, 240))
    px, py = room((-1.0, 1.0))
    decision = follower.step(0.0, px, py, None, (0.0, 0.0, 0.0))
    assert decision.mode is Mode.SEARCH and decision.target is None
    det = MotionDetector()
    for i in range(12):  # the walker behind the robot, on its left, moving away
        t = i / RATE_HZ
        movers = det.update(revolution(t, (0.0, 0.0, 0.0), (-1.0 - 0.2 * t, 1.0)), (0.0, 0.0, 0.0))
    assert movers
    px, py = revolution(t, (0.0, 0.0, 0.0), (-1.0 - 0.2 * t, 1.0)).points_xy()  # what the lidar sees of it
    decision = follower.step(t, px, py, None, (0.0, 0.0, 0.0), movers=movers)
    assert decision.target is not None and decision.target.bearing_rad > math.radians(90)
    assert decision.angular_rad_s > 0  # turning left, towards it
