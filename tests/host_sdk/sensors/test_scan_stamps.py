"""LaserScanner's stamps after late reads: each comes from its own revolution's measurement times,
ordered and bounded, and a late revolution leaves no trace in the stamps after it."""

from __future__ import annotations

import itertools

import pytest

from host_sdk.sensors import LaserScanData, LaserScanner, LidarScan
from host_sdk.sensors.laserscan import STEP_S
from tests.support.lidar_stream import FRONT, REAR, revolutions

COUNT = 40
LATE = 6
"""The revolution whose times come late."""
LATE_S = 0.12


def _per_push(scans: list[LidarScan]) -> tuple[LaserScanner, list[list[LaserScanData]]]:
    scanner = LaserScanner(360, clockwise=True)
    return scanner, [scanner.push(s) for s in scans]


@pytest.mark.parametrize("start", [REAR, FRONT], ids=["rear", "front"])
@pytest.mark.parametrize("hz", [5.5, 10.0])
def test_one_late_revolution_does_not_latch_later_stamps(hz: float, start: float) -> None:
    """From the third revolution after the late one, every message is stamped within 10 ms of a
    scanner fed the same revolutions with their true times."""
    _, control = _per_push(revolutions(hz, COUNT))
    _, got = _per_push(revolutions(hz, COUNT, late_s=LATE_S, late=LATE, start=start))
    for i in range(LATE + 3, COUNT):
        assert len(got[i]) == len(control[i]), f"revolution {i}: {len(got[i])} messages, control {len(control[i])}"
        for g, c in zip(got[i], control[i], strict=True):
            off_ms = (g.time_s - c.time_s) * 1e3
            assert abs(off_ms) <= 10, f"revolution {i}: stamp {off_ms:.0f} ms off"
    stamps = [m.time_s for msgs in got for m in msgs]
    assert all(b > a for a, b in itertools.pairwise(stamps)), "stamps strictly increase"


def _offsets_ms(hz: float, late_s: float) -> tuple[LaserScanner, list[list[float]]]:
    """Per driver revolution after the one the late stretch starts in, each message's stamp less
    the control's (ms); a message the control has and the scanner dropped is missing."""
    _, control = _per_push(revolutions(hz, COUNT))
    scanner, got = _per_push(revolutions(hz, COUNT, late_s=late_s, late=LATE))
    out = []
    for g, c in zip(got[LATE + 1 :], control[LATE + 1 :], strict=True):
        dropped = not g and c
        out.append([] if dropped else [round((a.time_s - b.time_s) * 1e3, 3) for a, b in zip(g, c, strict=True)])
    return scanner, out


def test_a_stamp_not_after_the_last_moves_just_after_it_and_is_counted() -> None:
    """At 10 Hz the revolution after one 120 ms late was measured before its stamp: it is stamped
    STEP_S after it (within its period), and the next at its own time again."""
    scanner, offsets = _offsets_ms(10.0, LATE_S)
    moved = round((LATE_S - 0.1 + STEP_S) * 1e3, 3)  # just after the late stamp, its own a period later
    assert offsets[:4] == [[120.0], [moved], [0.0], [0.0]]
    assert (scanner.retimed, scanner.dropped, scanner.refitted, scanner.rewritten) == (1, 0, 0, 1)


def test_a_revolution_that_cannot_follow_within_its_period_is_dropped() -> None:
    """After a revolution 390 ms late (almost four periods at 10 Hz), the two measured more than a
    period before its stamp are not published; the third is moved after it, the fourth is on time."""
    scanner, offsets = _offsets_ms(10.0, 0.39)
    moved = round((0.39 - 0.3 + STEP_S) * 1e3, 3)
    assert offsets[:5] == [[390.0], [], [], [moved], [0.0]]
    assert (scanner.retimed, scanner.dropped, scanner.rewritten) == (1, 2, 3)
    assert all(abs(ms) < 1e-3 for msgs in offsets[4:] for ms in msgs)


def test_a_revolution_refitted_from_mixed_times_is_counted() -> None:
    """A late stretch starting at the front splits across two messages: the one holding both late
    and true times is refitted from its own points, and counted."""
    scanner, got = _per_push(revolutions(10.0, COUNT, late_s=LATE_S, late=LATE, start=FRONT))
    assert scanner.refitted == 1 and scanner.rewritten >= 1
    assert sum(map(len, got)) == scanner.count
