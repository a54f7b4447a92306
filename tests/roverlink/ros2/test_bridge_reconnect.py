"""Losing the port: the bridge reports it (diagnostics ERROR), reconnects with backoff when the port
is back, and odometry carries on from where it was.

The board is `roverlink emulate --socket PORT` (a real process serving the emulator over TCP, as
a board behind a network serial adapter would be); stopping that process closes the connection
under the bridge, as pulling a USB cable does.
"""

from __future__ import annotations

import math
import time
import uuid
from collections.abc import Iterator
from pathlib import Path

import pytest
from ros_env import require_ros

require_ros()

from bridge_harness import ROOT, BridgeProcess, Probe, logged, values  # noqa: E402

from tests.support.emulate import EmulatorProcess  # noqa: E402


class EmulatorServer(EmulatorProcess):
    """`roverlink emulate --socket PORT` as a process; `port` 0 picks a free one."""

    def __init__(self, port: int = 0) -> None:
        args = ["--profile", "diffdrive-tb6612", "--quiet"]
        args += ["--socket", str(port), "--no-dtr-reset", "--eeprom", "saved"]
        super().__init__(*args, cwd=ROOT)
        assert self.url.startswith("socket://"), self.url
        self.port = int(self.url.rsplit(":", 1)[1])


@pytest.fixture
def served(ros: None, tmp_path: Path) -> Iterator[tuple[EmulatorServer, BridgeProcess, Probe]]:
    server = EmulatorServer()
    ns = f"/reconnect_{uuid.uuid4().hex[:6]}"
    params = {"profile": "diffdrive-tb6612", "reconnect_delay": 0.2, "reconnect_delay_max": 1.0}
    bridge = BridgeProcess(ns, server.url, tmp_path, params=params)
    probe = Probe(ns)
    servers = [server]
    try:
        with logged(bridge, probe):
            yield server, bridge, probe
    finally:
        for s in servers:
            if s.proc.poll() is None:
                s.stop()


def test_lost_port_is_reported_and_the_bridge_reconnects(served: tuple[EmulatorServer, BridgeProcess, Probe]) -> None:
    server, bridge, probe = served
    probe.wait_status("link", lambda s: s.level == b"\x00" and values(s)["connection"] == "connected", 20)
    assert probe.call("arm").success
    probe.drive(0.3, 0.5, 1.0)
    probe.drive(0.0, 0.0, 0.5)
    before = probe.wait_for("odometry at rest", lambda: _still(probe), 5)
    assert math.hypot(before.x, before.y) > 0.1

    server.stop()  # the port goes away under the bridge
    status = probe.wait_status("link", lambda s: s.level == b"\x02" and "reconnecting" in s.message, 5)
    assert values(status)["connection"] == "reconnecting"
    assert probe.wait_status("robot", lambda s: s.level == b"\x03").message == "no connection"
    # cmd_vel meanwhile is refused, and said so once
    probe.drive(0.2, 0.0, 0.3)
    status = probe.wait_status("robot", lambda s: "no connection" in values(s)["last refusal"])

    again = EmulatorServer(server.port)  # the port is back: a fresh board
    try:
        status = probe.wait_status("link", lambda s: s.level == b"\x00", 10)
        assert values(status)["reconnects"] == "1"
        assert probe.call("arm").success
        t = time.monotonic()
        after = probe.wait_message("odom", after=t).pose.pose.position
        assert math.hypot(after.x - before.x, after.y - before.y) < 1e-6  # odometry carries on
        probe.drive(0.3, 0.0, 0.5)
        moved = probe.last("odom").pose.pose.position
        assert math.hypot(moved.x - before.x, moved.y - before.y) > 0.05
    finally:
        again.stop()
    assert "lost the connection" in bridge.log()


def _still(probe: Probe) -> object:
    recent = probe.since("odom", time.monotonic() - 0.3)
    if len(recent) >= 3 and all(abs(r.msg.twist.twist.linear.x) < 1e-3 for r in recent):
        return recent[-1].msg.pose.pose.position
    return None
