"""Scan processing with known geometry: binning, the temporal median, motion compensation, the
spatial filter, and the three kinds of input (driver scans, LaserScan-shaped messages, arrays)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from host_sdk.body import LidarMount
from host_sdk.errors import CommandRangeError
from host_sdk.perception.scan import RawScan, ScanFilter, bin_points, spatial_filter
from host_sdk.sensors.scan import LidarScan

ANGLES = -math.pi + math.radians(0.72) * (np.arange(500) + 0.3)  # a YDLIDAR F4 revolution at 8 Hz


def wall_scan(distance: float, time_s: float = 0.0) -> RawScan:
    """A wall across the front at x = distance, nothing elsewhere (no return behind)."""
    with np.errstate(divide="ignore"):
        r = np.where(np.cos(ANGLES) > 0.2, distance / np.cos(ANGLES), np.nan)
    return RawScan.from_arrays(ANGLES, r, range_max_m=12.0, time_s=time_s)


def test_binning_keeps_the_nearest_return_per_bin() -> None:
    x = np.array([1.0, 2.0, 0.0])
    y = np.array([0.0, 0.001, 3.0])
    ranges = bin_points(x, y, 360)
    ahead = ranges[180]  # bin centred on +0.5 degrees: both forward points fall in bin 180
    assert ahead == pytest.approx(1.0)
    assert ranges[270] == pytest.approx(3.0)  # +90 degrees
    assert np.isnan(ranges[0])


def test_a_wall_ahead_comes_out_at_its_distance_in_the_base_frame() -> None:
    filt = ScanFilter(LidarMount(x_m=0.2))
    obstacles = filt.update(wall_scan(1.0))
    x, y = obstacles.points_xy()
    front = np.abs(y) < 0.3
    assert x[front] == pytest.approx(np.full(front.sum(), 1.2), abs=0.005)  # points sit on bin centres
    assert obstacles.range_at(0.0) == pytest.approx(1.2, abs=1e-3)
    assert obstacles.range_at(math.pi) == math.inf


def test_temporal_median_drops_a_one_revolution_echo_and_keeps_a_real_obstacle() -> None:
    filt = ScanFilter(temporal=3)
    base = wall_scan(3.0)
    echo = base.ranges_m.copy()
    echo[np.argmin(np.abs(ANGLES - 0.5))] = 0.4  # a stray return in one revolution only
    filt.update(base)
    filt.update(RawScan(ANGLES, echo))
    out = filt.update(base)
    assert out.range_at(0.5, math.radians(1)) == pytest.approx(3.0 / math.cos(0.5), rel=0.02)
    # A box appearing at 1 m is there once it has been seen in most of the last revolutions.
    box = base.ranges_m.copy()
    box[np.abs(ANGLES) < 0.1] = 1.0
    filt.update(RawScan(ANGLES, box))
    out = filt.update(RawScan(ANGLES, box))
    assert out.range_at(0.0) == pytest.approx(1.0, abs=0.01)


def test_the_median_is_motion_compensated() -> None:
    """Driving at a wall: earlier revolutions are moved into the current frame, so the filtered wall
    is where it is now, not where the older revolutions saw it."""
    filt = ScanFilter(temporal=3)
    for i, x in enumerate((0.0, 0.25, 0.5)):
        out = filt.update(wall_scan(2.0 - x, time_s=0.1 * i), pose=(x, 0.0, 0.0))
    assert out.range_at(0.0) == pytest.approx(1.5, abs=0.01)
    # Without poses the same revolutions give the median distance instead (1.75 m): the lag the
    # compensation removes.
    plain = ScanFilter(temporal=3)
    for x in (0.0, 0.25, 0.5):
        lagged = plain.update(wall_scan(2.0 - x))
    assert lagged.range_at(0.0) == pytest.approx(1.75, abs=0.01)


def test_turning_in_place_rotates_older_revolutions() -> None:
    filt = ScanFilter(temporal=3)
    post = np.where(np.abs(ANGLES - 0.0) < 0.02, 1.0, np.nan)  # a thin post straight ahead at 1 m
    filt.update(RawScan(ANGLES, post), pose=(0.0, 0.0, 0.0))
    turned = np.where(np.abs(ANGLES + 0.3) < 0.02, 1.0, np.nan)  # robot turned 0.3 rad left
    filt.update(RawScan(ANGLES, turned), pose=(0.0, 0.0, 0.3))
    out = filt.update(RawScan(ANGLES, turned), pose=(0.0, 0.0, 0.3))
    assert out.range_at(-0.3, math.radians(1.5)) == pytest.approx(1.0, abs=0.01)
    assert out.range_at(0.0, math.radians(1.5)) == math.inf


def test_spatial_filter_drops_isolated_far_returns_and_fills_holes() -> None:
    r = np.full(360, np.nan)
    r[100] = 4.0  # isolated, far: noise
    r[200:220] = 2.0
    r[210] = np.nan  # a hole in a surface
    r[300] = 0.5  # isolated but near: kept (a thin post close by must never vanish)
    out = spatial_filter(r, isolated_m=0.1, keep_near_m=1.0)
    assert np.isnan(out[100])
    assert out[210] == pytest.approx(2.0)
    assert out[300] == 0.5


def test_inputs_from_the_driver_a_laserscan_and_arrays_agree() -> None:
    ranges = np.where(np.cos(ANGLES) > 0.2, 1.5 / np.cos(ANGLES), np.nan)
    driver = LidarScan(
        "ydlidar-f4",
        0,
        ANGLES,
        ranges,
        np.zeros(ANGLES.shape, dtype=np.int64),
        np.linspace(0, 0.125, ANGLES.shape[0]),
        0.12,
        12.0,
    )
    msg = SimpleNamespace(
        angle_min=-math.pi + math.radians(0.72) * 0.3,
        angle_increment=math.radians(0.72),
        ranges=np.nan_to_num(ranges, nan=0.0).tolist(),
        range_min=0.12,
        range_max=12.0,
    )
    outs = [ScanFilter(temporal=1).update(s) for s in (driver, msg, RawScan.from_arrays(ANGLES, ranges))]
    for out in outs[1:]:
        np.testing.assert_allclose(out.ranges_m, outs[0].ranges_m, atol=1e-6, equal_nan=True)
    assert outs[0].time_s == 0.0


def test_out_of_range_values_are_no_return() -> None:
    scan = RawScan.from_arrays([0.0, 0.1, 0.2, 0.3], [0.05, np.inf, 0.0, 20.0], range_min_m=0.1, range_max_m=12)
    assert np.isnan(scan.ranges_m).all()


def test_bad_arguments_name_themselves() -> None:
    with pytest.raises(CommandRangeError, match="bins"):
        ScanFilter(bins=3)
    with pytest.raises(CommandRangeError, match="temporal"):
        ScanFilter(temporal=0)
    with pytest.raises(CommandRangeError, match="ranges_m"):
        RawScan.from_arrays([0.0, 1.0], [1.0])
    with pytest.raises(CommandRangeError, match="scan"):
        ScanFilter().update(42)  # type: ignore[arg-type]


def test_points_swallowed_by_the_blind_zone_are_kept_for_a_while() -> None:
    """A post seen 0.3 m ahead; the robot creeps up until the post is nearer than the lidar's minimum
    range (0.12 m) and vanishes from the scans: the filter still reports it, until `blind_hold_s`."""
    filt = ScanFilter(temporal=1, blind_hold_s=2.0)

    def post_at(x: float, t: float) -> RawScan:
        r = np.where(np.abs(ANGLES) < math.radians(8), x, np.nan)
        return RawScan.from_arrays(ANGLES, r, range_min_m=0.12, range_max_m=12.0, time_s=t)

    assert filt.update(post_at(0.3, 0.0), pose=(0.0, 0.0, 0.0)).range_at(0.0) == pytest.approx(0.3, abs=0.01)
    # 0.2 m on, the post is 0.1 m away: inside the blind zone, so the lidar returns nothing there.
    blind = RawScan.from_arrays(ANGLES, np.full(ANGLES.shape, np.nan), range_min_m=0.12, time_s=0.5)
    assert filt.update(blind, pose=(0.2, 0.0, 0.0)).range_at(0.0, math.radians(5)) == pytest.approx(0.1, abs=0.01)
    kept = filt.update(RawScan(ANGLES, blind.ranges_m, 1.5, 0.12), pose=(0.2, 0.0, 0.0))
    assert kept.range_at(0.0, math.radians(5)) == pytest.approx(0.1, abs=0.01)
    gone = filt.update(RawScan(ANGLES, blind.ranges_m, 2.6, 0.12), pose=(0.2, 0.0, 0.0))
    assert gone.range_at(0.0, math.radians(5)) == math.inf


def test_what_walks_into_the_blind_zone_of_a_standing_robot_is_not_kept() -> None:
    """Someone walks up to a robot standing still, into the blind zone, and on: the lidar last saw
    them at the zone's edge. A standing robot did not carry them in (they moved by themselves), so
    nothing is remembered there: kept, it hemmed the robot in for `blind_hold_s` after they left."""
    filt = ScanFilter(temporal=1, blind_hold_s=4.0)

    def person_at(x: float, t: float) -> RawScan:
        r = np.where(np.abs(ANGLES) < math.radians(8), x, np.nan)
        return RawScan.from_arrays(ANGLES, r, range_min_m=0.12, range_max_m=12.0, time_s=t)

    for i, x in enumerate((0.4, 0.25, 0.13)):
        filt.update(person_at(x, 0.1 * i), pose=(0.0, 0.0, 0.0))
    blind = RawScan.from_arrays(ANGLES, np.full(ANGLES.shape, np.nan), range_min_m=0.12, time_s=0.3)
    assert filt.update(blind, pose=(0.0, 0.0, 0.0)).range_at(0.0, math.radians(5)) == math.inf
    # The same edge point with the robot creeping 5 mm towards it is carried in, and kept.
    filt.reset()
    filt.update(person_at(0.13, 0.0), pose=(0.0, 0.0, 0.0))
    assert filt.update(blind, pose=(0.005, 0.0, 0.0)).range_at(0.0, math.radians(5)) == pytest.approx(0.125, abs=0.01)


def test_a_wall_crept_up_to_slowly_is_kept_in_the_blind_zone() -> None:
    """Creeping at 5 mm/s (0.5 mm per revolution at 10 Hz) up to a wall: its points enter the zone
    less than a millimetre nearer than the revolution before, but the robot's motion over the last
    second brought them in, so they are kept."""
    filt = ScanFilter(temporal=1)
    x, t = 0.0, 0.0
    while 0.2 - x >= 0.12:  # the wall at 0.2 m, seen until it is nearer than the minimum range
        wall = np.where(np.abs(ANGLES) < math.radians(8), (0.2 - x) / np.cos(ANGLES), np.nan)
        filt.update(RawScan.from_arrays(ANGLES, wall, range_min_m=0.12, time_s=t), pose=(x, 0.0, 0.0))
        x, t = x + 0.0005, t + 0.1
    blind = RawScan.from_arrays(ANGLES, np.full(ANGLES.shape, np.nan), range_min_m=0.12, time_s=t)
    assert filt.update(blind, pose=(x, 0.0, 0.0)).range_at(0.0, math.radians(5)) == pytest.approx(0.2 - x, abs=0.01)


def test_a_revolution_taken_while_spinning_is_deskewed_with_the_pose_of_each_return() -> None:
    # Spinning at 1.6 rad/s, a 0.125 s revolution's ends are 11 degrees apart, and they meet behind
    # the robot (the beam starts at -pi): a wall 1 m behind comes out torn in two unless each return
    # is placed with the heading the robot had when it was measured.
    rate, period = 1.6, 0.125
    times = period * (ANGLES + math.pi) / (2 * math.pi)  # the beam sweeps round from -pi
    heading = rate * times
    world = ANGLES + heading  # each beam's direction in the odometry frame at its time
    with np.errstate(divide="ignore"):
        r = np.where(np.cos(world) < -0.3, -1.0 / np.cos(world), np.nan)
    raw = RawScan.from_arrays(ANGLES, r, range_max_m=12.0, times_s=times)
    mid = (0.0, 0.0, rate * period / 2)

    def pose_at(t: float) -> tuple[float, float, float]:
        return 0.0, 0.0, rate * t

    def wall_x(obstacles: object) -> np.ndarray:
        x, y = obstacles.points_xy()  # type: ignore[attr-defined]
        th = mid[2]
        wx, wy = x * math.cos(th) - y * math.sin(th), x * math.sin(th) + y * math.cos(th)
        return wx[np.abs(wy) < 0.5]  # back into the odometry frame, where the wall is x = -1

    straight = wall_x(ScanFilter(temporal=1).update(raw, mid, pose_at=pose_at))
    assert straight == pytest.approx(-np.ones_like(straight), abs=0.01)
    torn = wall_x(ScanFilter(temporal=1).update(raw, mid))
    assert np.abs(torn + 1.0).max() > 0.03
    with pytest.raises(CommandRangeError, match="times_s"):
        RawScan.from_arrays(ANGLES, r, times_s=times[:-1])
