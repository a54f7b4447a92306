"""Nobody watching, nobody driving: following lasts on the driving page's keep-alive (not a watcher's)
unless the console runs autonomous; a failsafe, a reset or a lost link ends it and clears the drive
command; a watcher takes the wheel and the driver is told. The hub on a clock of the test's, the
server over real sockets."""

from __future__ import annotations

import json
import threading
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from test_console_pilot import StandIn
from websockets.sync.client import ClientConnection, connect

from host_sdk.console.access import Access
from host_sdk.console.hub import Drive, Hub
from host_sdk.console.pilot import ConsolePilot
from host_sdk.console.server import ConsoleServer
from host_sdk.geometry import geometry
from host_sdk.pose import Pose
from tests.support.wait import Deadline, wait_until

pytest.importorskip("cv2")
LIFETIME_S = 0.25
AT = Pose(0.0, 0.0, 0.0, time_s=0.0)


def console(*, autonomous: bool = False) -> tuple[ConsolePilot, Hub, list[float]]:
    now = [0.0]
    hub = Hub(command_lifetime_s=LIFETIME_S, clock=lambda: now[0], autonomous=autonomous)
    robot: Any = StandIn()
    return ConsolePilot(hub, robot, geometry("diffdrive-tb6612", None)), hub, now


def test_following_lasts_while_the_driving_page_keeps_it_alive() -> None:
    pilot, hub, now = console()
    hub.alive()
    hub.post(follow=True)
    pilot.command(AT)
    for t in (0.2, 0.4, 0.6):  # a keep-alive each 0.2 s: it goes on
        now[0] = t
        hub.alive()
        pilot.command(AT)
        assert pilot.following
    now[0] = 0.6 + LIFETIME_S + 0.01  # none for a lifetime: it ends, and stays ended
    pilot.command(AT)
    assert not pilot.following and "keeping it alive" in pilot.ended
    hub.alive()
    pilot.command(AT)
    assert not pilot.following  # the page coming back does not start it again: Follow does


def test_autonomous_following_needs_no_page() -> None:
    pilot, hub, now = console(autonomous=True)
    hub.post(follow=True)
    pilot.command(AT)
    now[0] = 60.0
    pilot.command(AT)
    assert pilot.following and hub.latest()[3]["autonomous"] is True


def test_a_halt_ends_following_and_clears_the_drive_command() -> None:
    pilot, hub, _ = console(autonomous=True)  # even autonomous: a failsafe ends it
    hub.post(follow=True, drive=Drive(0.3, 0.0, 0.0))
    pilot.command(AT)
    pilot.halt("failsafe COMM_TIMEOUT")
    assert not pilot.following and pilot.ended == "following ended: failsafe COMM_TIMEOUT"
    assert hub.take().drive is None
    assert pilot.command(AT)[:2] == (0.0, 0.0)
    assert hub.latest()[3]["ended"] == "following ended: failsafe COMM_TIMEOUT"


def until(check: Callable[[], Any], timeout_s: float = 5.0) -> Any:
    return wait_until(check, timeout_s, "the condition")


def receive(ws: ClientConnection, kind: str) -> dict[str, Any]:
    deadline = Deadline(5.0)
    while True:
        msg = ws.recv(timeout=deadline.remaining(0.01))
        if isinstance(msg, str) and (found := json.loads(msg))["type"] == kind:
            return found  # type: ignore[no-any-return]


@pytest.fixture
def served() -> Iterator[tuple[ConsoleServer, Hub, threading.Event]]:
    hub = Hub(command_lifetime_s=LIFETIME_S)
    stops = threading.Event()
    server = ConsoleServer(hub, Access.for_host("127.0.0.1"), 0, on_stop=stops.set)
    server.start()
    yield server, hub, stops
    server.close()


def page(server: ConsoleServer) -> ClientConnection:
    base = f"127.0.0.1:{server.port}"
    return connect(f"ws://{base}/ws", origin=f"http://{base}", open_timeout=5)


def test_only_the_drivers_keep_alive_counts_and_a_watcher_takes_the_wheel(
    served: tuple[ConsoleServer, Hub, threading.Event],
) -> None:
    server, hub, stops = served
    with page(server) as first, page(server) as second:
        assert receive(first, "hello")["keepalive_s"] == pytest.approx(LIFETIME_S / 3)
        second.send(json.dumps({"type": "alive"}))  # nobody drives yet: a keep-alive makes no driver
        first.send(json.dumps({"type": "follow", "on": True}))
        until(lambda: hub.alive_s > 0)
        heard = hub.alive_s
        second.send(json.dumps({"type": "alive"}))  # a watcher's: kept nothing alive
        first.send(json.dumps({"type": "alive"}))
        until(lambda: hub.alive_s > heard)
        second.send(json.dumps({"type": "drive", "linear": 0.1, "angular": 0.0}))
        assert "take the wheel" in receive(second, "error")["error"]
        first.send(json.dumps({"type": "drive", "linear": 0.2, "angular": 0.0}))
        until(lambda: hub.take().drive is not None)
        second.send(json.dumps({"type": "take"}))
        assert "took the wheel" in receive(first, "notice")["text"]
        taken = hub.take()
        assert taken.drive is None and taken.follow is False  # the robot stops for the new driver
        first.send(json.dumps({"type": "drive", "linear": 0.2, "angular": 0.0}))
        assert "another browser is driving" in receive(first, "error")["error"]
        second.send(json.dumps({"type": "drive", "linear": -0.1, "angular": 0.0}))
        until(lambda: (d := hub.take().drive) is not None and d.linear_m_s == -0.1)
        second.send(json.dumps({"type": "dismiss", "id": "none"}))
        assert "dismiss" in receive(second, "error")["error"]  # said, and the socket goes on
        second.close()  # the driver leaves: its command and keep-alive go at once
        until(lambda: hub.alive_s == -float("inf") and hub.take().drive is None)
        assert not stops.is_set()


def test_a_driver_gone_quiet_holds_the_wheel_no_more() -> None:
    """A driving tab that went quiet (frozen, hidden, or the same page back over a new socket while
    the old one is not closed yet) does not lock the others out: after DRIVER_GONE_S without a word
    from it, the next browser to send a command drives, and the quiet one is told."""
    from host_sdk.console.server import DRIVER_GONE_S

    now = [100.0]
    hub = Hub(command_lifetime_s=LIFETIME_S, clock=lambda: now[0])
    server = ConsoleServer(hub, Access.for_host("127.0.0.1"), 0, on_stop=lambda: None)
    server.start()
    try:
        with page(server) as first, page(server) as second:
            first.send(json.dumps({"type": "follow", "on": True}))
            until(lambda: hub.alive_s == 100.0)
            now[0] += DRIVER_GONE_S - 0.1  # quiet, but not for long enough
            second.send(json.dumps({"type": "drive", "linear": 0.1, "angular": 0.0}))
            assert "another browser is driving" in receive(second, "error")["error"]
            now[0] += 0.2
            second.send(json.dumps({"type": "drive", "linear": 0.1, "angular": 0.0}))
            until(lambda: (d := hub.take().drive) is not None and d.linear_m_s == 0.1)
            assert "gone quiet" in receive(first, "notice")["text"]
            first.send(json.dumps({"type": "drive", "linear": 0.2, "angular": 0.0}))
            assert "another browser is driving" in receive(first, "error")["error"]
    finally:
        server.close()
