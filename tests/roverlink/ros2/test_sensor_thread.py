"""A sensor thread of the node survives any exception: it logs it once, shows it in its
diagnostics status, and opens the device again after RETRY_S; the lidar's status shows the scan
stamps its scanner rewrote (unit level: a stand-in node)."""

from __future__ import annotations

import functools
import itertools
import math
import threading
import time
from types import SimpleNamespace
from typing import Any

import pytest
from ros_env import require_ros

require_ros()

from host_sdk.sensors import LidarScan, SensorClosedError  # noqa: E402
from host_sdk.sensors.scan import LidarCounters  # noqa: E402
from roverlink.ros2 import sensors  # noqa: E402
from roverlink.ros2.diagnostics import ERROR, OK, WARN  # noqa: E402
from roverlink.ros2.stamp_rewrites import StampRewrites  # noqa: E402
from tests.support.lidar_stream import revolutions  # noqa: E402
from tests.support.wait import wait_until  # noqa: E402


class _Logger:
    def __init__(self) -> None:
        self.lines: list[tuple[str, str]] = []

    def warning(self, text: str) -> None:
        self.lines.append(("warning", text))

    def error(self, text: str) -> None:
        self.lines.append(("error", text))


class _Node:
    def __init__(self, clock: Any = time.monotonic) -> None:
        self.logger = _Logger()
        self.published: list[Any] = []
        self.clock = clock

    def get_logger(self) -> _Logger:
        return self.logger

    def create_publisher(self, *_: Any) -> Any:
        return SimpleNamespace(publish=self.published.append)

    def get_clock(self) -> Any:
        return SimpleNamespace(now=lambda: SimpleNamespace(nanoseconds=round(self.clock() * 1e9)))


class _Device:
    counters = None

    def close(self) -> None:
        raise ValueError("closing a broken device fails too")


class _Flaky(sensors.SensorPublisher):
    """Reads fail with a bug's exception for the first opens, then the device works."""

    kind = "lidar"

    def __init__(self, node: Any, failing_opens: int) -> None:
        self.failing_opens = failing_opens
        self.published = threading.Event()
        super().__init__(node, "emudev://test/lidar", "laser")

    def counters(self) -> dict[str, int]:
        return {}

    def _open(self) -> _Device:
        return _Device()

    def _read_and_publish(self, device: Any) -> None:
        if self.opened <= self.failing_opens:
            raise IndexError("index 0 is out of bounds for axis 0 with size 0")
        self.published.set()
        time.sleep(0.001)  # a device's read blocks; this one returns at once


def test_an_unexpected_exception_is_logged_once_reported_and_recovered_from(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sensors, "RETRY_S", 0.05)
    node = _Node()
    pub = _Flaky(node, failing_opens=3)
    try:
        wait_until(lambda: pub.opened >= 3, 5.0, "three opens", fail=False)
        report = pub.report("roverlink")
        if not pub.published.is_set():  # still failing: the status says what broke
            assert report.level == ERROR and "unexpected IndexError" in report.message
        assert pub.published.wait(5.0), "the thread opened the device again and published"
        assert pub._thread.is_alive()
        errors = [text for level, text in node.logger.lines if level == "error"]
        assert len(errors) == 1 and "unexpected IndexError: index 0 is out of bounds" in errors[0]
        wait_until(lambda: pub.report("roverlink").level == OK, 5.0, "the status back at OK", fail=False)
        assert pub.report("roverlink").level == OK and pub.error == ""
    finally:
        pub.close()


class _LateLidar:
    """A lidar (Lidar.open's stand-in) serving revolutions with one 120 ms late, then nothing
    until released."""

    spec = SimpleNamespace(clockwise=True)

    def __init__(self, scans: list[LidarScan]) -> None:
        self.scans = scans
        self.counters = LidarCounters()
        self.served, self.release = threading.Event(), threading.Event()
        self.now = 0.0
        self.port = SimpleNamespace(clock=lambda: self.now)

    def open(self, url: str, model: str, baud: int | None = None) -> _LateLidar:
        return self

    def start(self) -> None:
        pass

    def read_scan(self, timeout_s: float) -> LidarScan:
        if not self.scans:
            self.served.set()
            self.release.wait()
            raise SensorClosedError("released")
        scan = self.scans.pop(0)
        self.now = max(self.now, float(scan.measurement_times_s[-1]))  # read once its last point is in
        return scan

    def close(self) -> None:
        pass


def test_the_lidar_status_warns_and_counts_rewritten_scan_stamps(monkeypatch: pytest.MonkeyPatch) -> None:
    lidar = _LateLidar(revolutions(10.0, 30, late_s=0.12, late=6))
    monkeypatch.setattr(sensors, "Lidar", lidar)
    monkeypatch.setattr(sensors, "QUIET_S", math.inf)  # the status is read whenever the test gets to it
    monkeypatch.setattr(sensors, "StampRewrites", functools.partial(StampRewrites, window_s=math.inf))
    node = _Node(clock=lambda: lidar.now)  # ROS time is the port's clock here
    pub = sensors.LidarPublisher(node, "emudev://test/lidar", "rplidar-a1", "laser", 360)  # type: ignore[arg-type]
    try:
        assert lidar.served.wait(10.0), "the thread read every revolution"
        stamps = [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in node.published]
        assert len(stamps) == pub.scanner.count and all(b > a for a, b in itertools.pairwise(stamps))
        report = pub.report("roverlink")
        assert report.level == WARN and "scan stamps rewritten (late reads): 1 in the last" in report.message
        assert dict(report.values)["scan stamps retimed"] == "1"
    finally:
        pub._stop.set()
        lidar.release.set()
        pub.close()
