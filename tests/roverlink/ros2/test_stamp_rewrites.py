"""The lidar's diagnostics status and the scan stamps its LaserScanner rewrote (plain Python, on a
virtual clock): counted over the node's life, WARN while any is recent."""

from __future__ import annotations

from host_sdk.sensors import LaserScanner
from roverlink.ros2.diagnostics import ERROR, OK, WARN, Report
from roverlink.ros2.stamp_rewrites import StampRewrites
from tests.support.lidar_stream import revolutions

HZ = 10.0
OK_REPORT = Report(OK, "roverlink: lidar", "10.0 Hz", "emudev://x/lidar", (("url", "emudev://x/lidar"),))


def _values(report: Report) -> dict[str, str]:
    return dict(report.values)


def test_a_rewritten_stamp_warns_for_the_window_with_the_counts() -> None:
    log = StampRewrites(window_s=5.0)
    scanner = LaserScanner(360, clockwise=True)
    retimed_at = None
    for i, scan in enumerate(revolutions(HZ, 30, late_s=0.12, late=6)):
        scanner.push(scan)
        log.update(scanner, i / HZ)  # the node's clock: one revolution per read
        if not scanner.retimed:
            assert log.apply(OK_REPORT, i / HZ).level == OK
        elif retimed_at is None:
            retimed_at = i / HZ
    assert scanner.retimed == 1 and retimed_at is not None
    report = log.apply(OK_REPORT, retimed_at + 4.9)
    assert report.level == WARN and report.message == "10.0 Hz; scan stamps rewritten (late reads): 1 in the last 5 s"
    assert _values(report)["scan stamps retimed"] == "1" and _values(report)["scans dropped (no ordered stamp)"] == "0"
    later = log.apply(OK_REPORT, retimed_at + 5.1)
    assert later.level == OK and later.message == "10.0 Hz" and _values(later)["scan stamps retimed"] == "1"


def test_counts_carry_on_across_a_new_scanner_and_a_quiet_stream_stays_ok() -> None:
    log = StampRewrites()
    first = LaserScanner(360, clockwise=True)
    for scan in revolutions(HZ, 20, late_s=0.39, late=6):
        first.push(scan)
    log.update(first, 10.0)
    again = LaserScanner(360, clockwise=True)  # the lidar reopened: its scanner counts from zero
    for scan in revolutions(HZ, 20):
        again.push(scan)
        log.update(again, 20.0)
    assert log.totals == {"refitted": 0, "retimed": 1, "dropped": 2}
    assert log.apply(OK_REPORT, 20.0).level == OK


def test_an_error_keeps_its_level_and_message() -> None:
    log = StampRewrites()
    scanner = LaserScanner(360, clockwise=True)
    for scan in revolutions(HZ, 20, late_s=0.12, late=6):
        scanner.push(scan)
    log.update(scanner, 1.0)
    failed = Report(ERROR, "roverlink: lidar", "no data", "emudev://x/lidar")
    report = log.apply(failed, 1.0)
    assert (report.level, report.message) == (ERROR, "no data")
    assert _values(report)["scan stamps retimed"] == "1"
