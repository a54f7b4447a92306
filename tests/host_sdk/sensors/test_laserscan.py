"""LaserScanner on hand-made revolutions: the rear cut, REP 117's range classes, the time line."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from host_sdk.sensors import LaserScanner, LidarScan

RATE = 2000.0  # samples per second
HZ = 5.0  # revolutions per second


def _stream(seconds: float, *, clockwise: bool, ranges: object = 2.0, t0: float = 0.0) -> list[LidarScan]:
    """Front-cut revolutions (as the drivers deliver them) of a device turning at HZ."""
    n = round(seconds * RATE)
    t = t0 + np.arange(n) / RATE
    turned = 2 * math.pi * HZ * (t - t0) + 0.3  # starts a little past the front
    device = np.mod(turned, 2 * math.pi)  # device angle, its own direction
    rad = np.angle(np.exp(1j * (-device if clockwise else device)))
    r = np.broadcast_to(np.asarray(ranges, dtype=np.float64), (n,)) if np.ndim(ranges) == 0 else np.asarray(ranges)
    cuts = np.flatnonzero(np.diff(np.floor(turned / (2 * math.pi))) > 0) + 1
    out = []
    for i, (lo, hi) in enumerate(zip([0, *cuts], [*cuts, n], strict=True)):
        out.append(
            LidarScan(
                "rplidar-a1",
                i,
                rad[lo:hi],
                r[lo:hi].copy(),
                np.full(hi - lo, 10),
                t[lo:hi],
                0.15,
                12.0,
                measured_s=t[lo:hi],
            )
        )
    return out


def _only(s: LidarScan, k: np.ndarray) -> LidarScan:
    """The scan's points where k is True."""
    t = s.times_s[k]
    return LidarScan(
        s.device, s.index, s.angles_rad[k], s.ranges_m[k], s.qualities[k], t, s.range_min_m, s.range_max_m, measured_s=t
    )


@pytest.mark.parametrize("clockwise", [True, False])
def test_each_message_is_one_revolution_from_the_rear_with_its_rays_times(clockwise: bool) -> None:
    scanner = LaserScanner(360, clockwise=clockwise)
    msgs = [m for scan in _stream(2.0, clockwise=clockwise) for m in scanner.push(scan)]
    assert len(msgs) >= 8  # the half revolution before the first rear cut is not published
    for m in msgs:
        assert m.angle_min == -math.pi and m.angle_increment == pytest.approx(math.pi / 180)
        assert m.scan_time_s == pytest.approx(1 / HZ, rel=1e-6)
        assert m.time_increment_s == pytest.approx((-1 if clockwise else 1) / HZ / 360, rel=1e-6)
        # Ray i at angle -pi + i deg: the device was there at stamp + i * increment.
        angle = -math.pi + np.arange(360) * m.angle_increment
        device = np.mod(-angle if clockwise else angle, 2 * math.pi)
        t = m.ray_times_s()
        turned = 2 * math.pi * HZ * t + 0.3
        assert np.abs(np.angle(np.exp(1j * (np.mod(turned, 2 * math.pi) - device)))).max() < 1e-6
        assert np.ptp(t) == pytest.approx(359 / 360 / HZ, rel=1e-6)  # one revolution, contiguous
        assert (m.ranges_m == 2.0).all()
    assert np.diff([m.time_s for m in msgs]) == pytest.approx(1 / HZ)


def test_rep117_classes_too_close_no_return_beyond_range_and_unsampled() -> None:
    n = round(2.0 * RATE)
    ranges = np.full(n, 3.0)
    angle_deg = np.degrees(np.mod(2 * math.pi * HZ * np.arange(n) / RATE + 0.3, 2 * math.pi))
    ranges[(angle_deg > 10) & (angle_deg < 20)] = np.nan  # no return on the wire
    ranges[(angle_deg > 30) & (angle_deg < 40)] = 0.05  # below range_min (0.15)
    ranges[(angle_deg > 50) & (angle_deg < 60)] = 20.0  # beyond range_max (12)
    keep = ~((angle_deg > 70) & (angle_deg < 80))  # no sample at all
    scans = _stream(2.0, clockwise=True, ranges=ranges)
    scans = [_only(s, keep[np.searchsorted(np.arange(n) / RATE, s.times_s)]) for s in scans]
    scanner = LaserScanner(360, clockwise=True)
    msg = [m for s in scans for m in scanner.push(s)][-1]
    deg = -np.degrees(-math.pi + np.arange(360) * msg.angle_increment) % 360  # device angle of each ray
    r = msg.ranges_m
    inside = lambda lo, hi: (deg > lo + 1) & (deg < hi - 1)  # noqa: E731
    assert np.isposinf(r[inside(10, 20)]).all()
    assert np.isneginf(r[inside(30, 40)]).all()
    assert np.isposinf(r[inside(50, 60)]).all()
    assert np.isnan(r[inside(70, 80)]).all()
    assert (r[inside(100, 350)] == 3.0).all()
    assert (msg.intensities[inside(10, 20)] == 0).all() and (msg.intensities[inside(100, 350)] == 10).all()


def test_a_gap_in_the_stream_starts_afresh() -> None:
    scanner = LaserScanner(360, clockwise=True)
    first = [m for s in _stream(1.0, clockwise=True) for m in scanner.push(s)]
    later = [m for s in _stream(1.0, clockwise=True, t0=5.0) for m in scanner.push(s)]
    assert first and later
    assert later[0].time_s > 5.0 and np.ptp(later[0].ray_times_s()) < 1 / HZ  # nothing of before in it


def test_bins_below_eight_are_refused() -> None:
    with pytest.raises(ValueError, match="bins = 4"):
        LaserScanner(4, clockwise=True)


def test_late_reads_never_turn_the_time_line_round_or_send_a_message_back_in_time() -> None:
    """A starved host reads in bursts: its upper-bound times jump. Each message keeps the device's
    direction and rate, and no stamp goes back past the one before."""
    scans = _stream(3.0, clockwise=True)
    for index, late in ((5, "half"), (8, "all"), (9, "all")):
        s = scans[index]
        t = s.measurement_times_s.copy()
        if late == "half":
            t[t.shape[0] // 2 :] += 0.3
        else:
            t += 0.4
        scans[index] = LidarScan(
            s.device, s.index, s.angles_rad, s.ranges_m, s.qualities, t, s.range_min_m, s.range_max_m, measured_s=t
        )
    scanner = LaserScanner(360, clockwise=True)
    msgs = [m for scan in scans for m in scanner.push(scan)]
    nominal = 1 / HZ / 360
    for m in msgs:
        assert -1.25 * nominal <= m.time_increment_s <= -0.75 * nominal
    stamps = [m.time_s for m in msgs]
    assert all(b > a for a, b in itertools.pairwise(stamps)), stamps
    assert scanner.refitted >= 1 and scanner.retimed + scanner.dropped >= 1
