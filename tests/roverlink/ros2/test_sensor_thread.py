"""A sensor thread of the node survives any exception: it logs it once, shows it in its
diagnostics status, and opens the device again after RETRY_S (unit level: a stand-in node)."""

from __future__ import annotations

import threading
import time
from typing import Any

import pytest
from ros_env import require_ros

require_ros()

from roverlink.ros2 import sensors  # noqa: E402
from roverlink.ros2.diagnostics import ERROR, OK  # noqa: E402
from tests.support.wait import wait_until  # noqa: E402


class _Logger:
    def __init__(self) -> None:
        self.lines: list[tuple[str, str]] = []

    def warning(self, text: str) -> None:
        self.lines.append(("warning", text))

    def error(self, text: str) -> None:
        self.lines.append(("error", text))


class _Node:
    def __init__(self) -> None:
        self.logger = _Logger()

    def get_logger(self) -> _Logger:
        return self.logger


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
