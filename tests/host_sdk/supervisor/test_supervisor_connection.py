"""The port kept open: connecting with backoff, giving up on what a retry cannot fix, and a lost
port (a real `roverlink emulate --socket` process stopped and started again, as a USB adapter
pulled out and plugged back in) opened again by the supervisor with the odometry carried on."""

from __future__ import annotations

import itertools
import threading
import time
from collections.abc import Callable
from typing import Any

from host_sdk import Robot, TransportError
from host_sdk.supervisor import Connection, Supervisor
from tests.support.emulate import EmulatorProcess
from tests.support.wait import wait_until


def until(check: Callable[[], Any], timeout_s: float, what: str) -> Any:
    return wait_until(check, timeout_s, what, poll_s=0.02)


def test_connection_retries_with_doubling_delays_then_connects() -> None:
    calls: list[float] = []
    connected = threading.Event()

    def connect() -> Robot:
        calls.append(time.monotonic())
        if len(calls) <= 3:
            raise TransportError("no such port", "/dev/ttyACM9")
        return Robot.connect("emu://diffdrive-tb6612?clock=virtual")

    conn = Connection(connect, on_connected=lambda r: connected.set(), on_lost=lambda r, w: None, delay_s=0.05)
    conn.start()
    assert connected.wait(5)
    robot = conn.stop()
    assert robot is not None
    robot.close()
    gaps = [b - a for a, b in itertools.pairwise(calls)]
    assert [round(g / 0.05) for g in gaps] == [1, 2, 4]
    assert conn.fatal is None and conn.attempts == 0


def test_connection_gives_up_on_errors_a_retry_cannot_fix() -> None:
    def connect() -> Robot:
        return Robot.connect("emu://no-such-robot")

    conn = Connection(connect, on_connected=lambda r: None, on_lost=lambda r, w: None)
    conn.start()
    assert conn.stop() is None
    assert conn.state == "closed" and conn.fatal is not None and "no-such-robot" in str(conn.fatal)


class Board(EmulatorProcess):
    """`roverlink emulate --socket PORT`: a board behind a network serial adapter."""

    def __init__(self, port: int = 0) -> None:
        super().__init__(
            "--profile", "diffdrive-tb6612", "--quiet", "--socket", str(port), "--no-dtr-reset", "--eeprom", "saved"
        )
        self.port = int(self.url.rsplit(":", 1)[1])


def test_a_lost_port_is_opened_again_and_the_odometry_carries_on() -> None:
    board = Board()
    again: Board | None = None
    sup: Supervisor | None = None
    try:
        sup = Supervisor.connect(board.url, profile="diffdrive-tb6612", delay_s=0.1, delay_max_s=0.4)
        first = sup.robot
        assert sup.arm()
        t0 = time.monotonic()
        while time.monotonic() - t0 < 0.6:
            sup.drive(0.3, 0.0)
            sup.sleep(0.05)
        sup.stop_driving()
        x = until(lambda: (p := sup.robot.odometry.pose).linear_m_s == 0 and p.x_m, 5, "the robot standing")
        halts = sup.health().halts
        board.stop()  # the port goes away under the robot
        lost = until(lambda: (h := sup.health()).link == "reconnecting" and h, 5, "the lost port reported")
        assert not lost.armed and lost.halts > halts
        banner = lost.banner()
        assert banner is not None and "port lost" in banner.text and "opening" in banner.hint
        assert not sup.drive(0.2, 0.0) and not sup.arm()  # refused as state, not raised
        assert [r.what for r in sup.health().refusals] == ["ARM"]
        again = Board(board.port)  # plugged in again: a fresh board
        until(lambda: sup.health().link == "up", 15, "the port opened again")
        assert sup.robot is not first and sup.robot.state == "disarmed"  # waits for the user to arm
        assert abs(sup.robot.odometry.pose.x_m - x) < 1e-6
        assert sup.arm() and sup.health().armed
    finally:
        if sup is not None:
            sup.close()
        for b in (board, again):
            if b is not None:
                b.stop()
