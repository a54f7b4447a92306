"""The I/O thread's loop (host_sdk/robot/runner.py ThreadedRunner) against a scripted session and port:
how long each read may sleep, with callbacks that take their time."""

from __future__ import annotations

import queue
from typing import Any, cast

import pytest

from host_sdk.robot.runner import ThreadedRunner
from host_sdk.session import Event, Session
from host_sdk.transport import Transport

DEADLINE_S = 0.010
"""When the scripted session's next timer is due (a paced setpoint's slot)."""


class ScriptedPort:
    """A port whose clock the test sets, and whose reads return what the test queues."""

    url = "scripted://"
    virtual = False

    def __init__(self) -> None:
        self.now = 0.0
        self.chunks: queue.Queue[bytes | None] = queue.Queue()
        self.timeouts: queue.Queue[float] = queue.Queue()

    def clock(self) -> float:
        return self.now

    def read(self, timeout_s: float) -> bytes:
        self.timeouts.put(timeout_s)
        chunk = self.chunks.get(timeout=10.0)
        if chunk is None:
            raise OSError("scripted port closed")
        return chunk

    def write(self, data: bytes) -> None:
        pass

    def close(self) -> None:
        self.chunks.put(None)


class ScriptedSession:
    """Due at DEADLINE_S; one event for every read that brought bytes."""

    error = None

    def __init__(self) -> None:
        self._events: list[Any] = []

    def start(self, now: float) -> None:
        pass

    def receive(self, data: bytes, now: float) -> None:
        self._events.append(object())

    def poll(self, now: float) -> None:
        pass

    def outgoing(self) -> bytes:
        return b""

    def take_events(self) -> list[Any]:
        events, self._events = self._events, []
        return events

    def next_deadline(self, now: float) -> float:
        return DEADLINE_S

    def fail(self, error: BaseException) -> None:
        self.error = error

    def close(self) -> None:
        pass


def test_a_read_after_slow_callbacks_sleeps_only_until_the_next_deadline() -> None:
    """A FEEDBACK read at 2.6 ms whose callbacks run until 6 ms (a ROS node publishing): the next
    read waits until the deadline at 10 ms, 4 ms, not the 7.4 ms left when the bytes came."""
    port = ScriptedPort()

    def slow_callbacks(events: list[Event]) -> None:
        port.now = 0.006

    runner = ThreadedRunner(cast(Session, ScriptedSession()), cast(Transport, port), slow_callbacks)
    runner.start()
    try:
        first = port.timeouts.get(timeout=10.0)
        assert first == pytest.approx(DEADLINE_S)
        port.now = 0.0026
        port.chunks.put(b"feedback")
        assert port.timeouts.get(timeout=10.0) == pytest.approx(DEADLINE_S - 0.006)
    finally:
        runner.abandon()
