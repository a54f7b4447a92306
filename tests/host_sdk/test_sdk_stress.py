"""The SDK under stress: concurrent requests, a runner that fails, a port that disappears.

Each test here is the regression test of a defect found by hammering the public API from several
threads and with failing transports.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from host_sdk import Robot
from host_sdk.errors import LinkBrokenError, RoverLinkError, TransportError
from host_sdk.transport import Transport, open_transport
from tests.support.wait import wait_until

ROUNDS = 4
CALLS = 8


def _hammer(robot: Robot, jobs: list[Callable[[int], Any]]) -> list[BaseException]:
    """Run each job(k) for k in 0..CALLS-1 on its own thread, all at once; returns what they raised."""
    errors: list[BaseException] = []
    start = threading.Barrier(len(jobs))

    def run(job: Callable[[int], Any]) -> None:
        start.wait()
        try:
            for k in range(CALLS):
                job(k)
        except BaseException as exc:  # the assertion shows it
            errors.append(exc)

    workers = [threading.Thread(target=run, args=(job,)) for job in jobs]
    for w in workers:
        w.start()
    for w in workers:
        w.join(timeout=60)
    assert not any(w.is_alive() for w in workers), "a request hung"
    return errors


@pytest.mark.parametrize("clock", ["virtual", "real"])
def test_concurrent_config_changes_to_different_fields_all_stick(clock: str) -> None:
    with Robot.connect(f"emu://diffdrive-tb6612?clock={clock}") as robot:
        for r in range(ROUNDS):
            speeds = [300 + 10 * r + k for k in range(CALLS)]
            accels = [1000 + 10 * r + k for k in range(CALLS)]
            seen: list[tuple[str, int, int]] = []

            def a(k: int, speeds: list[int] = speeds, seen: list[tuple[str, int, int]] = seen) -> None:
                got = robot.set_config(max_wheel_speed_mm_s=speeds[k])
                assert got.max_wheel_speed_mm_s == speeds[k]
                seen.append(("a", k, got.accel_limit_mm_s2))

            def b(k: int, accels: list[int] = accels, seen: list[tuple[str, int, int]] = seen) -> None:
                got = robot.set_config(accel_limit_mm_s2=accels[k])
                assert got.accel_limit_mm_s2 == accels[k]
                seen.append(("b", k, got.max_wheel_speed_mm_s))

            assert _hammer(robot, [a, b]) == []
            board = robot.read_config()
            assert (board.max_wheel_speed_mm_s, board.accel_limit_mm_s2) == (speeds[-1], accels[-1])
            fw = _firmware_config(robot)
            assert (fw.max_wheel_speed_mm_s, fw.accel_limit_mm_s2) == (speeds[-1], accels[-1])


def test_concurrent_changes_to_one_field_end_with_a_written_value() -> None:
    with Robot.connect("emu://diffdrive-tb6612?clock=virtual") as robot:
        written = {400 + k for k in range(CALLS)} | {500 + k for k in range(CALLS)}
        jobs = [
            lambda k: robot.set_config(max_wheel_speed_mm_s=400 + k),
            lambda k: robot.set_config(max_wheel_speed_mm_s=500 + k),
            lambda k: robot.set_pid(kp=1.0 + k / 10, wheel=k % 2),
            lambda k: robot.set_pid(ki=2.0 + k / 10),
        ]
        assert _hammer(robot, jobs) == []
        assert robot.read_config().max_wheel_speed_mm_s in {400 + CALLS - 1, 500 + CALLS - 1}
        assert robot.config.max_wheel_speed_mm_s in written
        for wheel in (0, 1):
            gains = robot.pid(wheel)
            assert gains.ki == pytest.approx(2.0 + (CALLS - 1) / 10)  # every wheel, last call wins
        assert robot.pid(1).kp == pytest.approx(1.0 + (CALLS - 1) / 10)  # k = 7 went to wheel 1


def _firmware_config(robot: Robot) -> Any:
    with robot.transport.locked() as emu:  # type: ignore[attr-defined]
        return emu.truth.firmware.config


# -- a runner that fails ---------------------------------------------------------------------------------
class FailingTransport(Transport):
    """Wraps a real transport; `fail_with` makes the next read raise it."""

    def __init__(self, inner: Transport) -> None:
        self.inner = inner
        self.url = inner.url
        self.virtual = inner.virtual
        self.profile = inner.profile
        self.device = inner.device
        self.fail_with: BaseException | None = None

    def read(self, timeout_s: float) -> bytes:
        if self.fail_with is not None:
            raise self.fail_with
        return self.inner.read(timeout_s)

    def write(self, data: bytes) -> None:
        self.inner.write(data)

    def close(self) -> None:
        self.inner.close()

    def clock(self) -> float:
        return self.inner.clock()

    def locked(self) -> Any:
        return self.inner.locked()  # type: ignore[attr-defined]


@pytest.fixture
def thread_tracebacks() -> Iterator[list[threading.ExceptHookArgs]]:
    """Tracebacks printed by dying threads (there must be none: a runner reports, it does not die)."""
    seen: list[threading.ExceptHookArgs] = []
    old = threading.excepthook
    threading.excepthook = seen.append
    try:
        yield seen
    finally:
        threading.excepthook = old


@pytest.mark.parametrize("clock", ["real", "virtual"])
def test_a_failing_runner_breaks_the_robot_at_once_wakes_waiters_and_chains_the_cause(
    clock: str, thread_tracebacks: list[threading.ExceptHookArgs]
) -> None:
    transport = FailingTransport(open_transport(f"emu://diffdrive-tb6612?clock={clock}"))
    robot = Robot.connect(transport=transport)
    try:
        robot.arm()
        robot.drive(0.2, 0.0)
        boom = ValueError("a bug in a layer below")
        woke: list[BaseException] = []
        waiting = threading.Event()

        def waiter() -> None:
            waiting.set()
            try:
                robot.wait_feedback(timeout_s=30.0)  # must not sit out its timeout
                robot.wait_feedback(timeout_s=30.0)
            except BaseException as exc:
                woke.append(exc)

        if clock == "real":
            t = threading.Thread(target=waiter)
            t.start()
            waiting.wait()
            transport.fail_with = boom
            t.join(timeout=5.0)
            assert not t.is_alive(), "a waiter was not woken"
            wait_until(lambda: robot.state == "broken", 1.0, "the robot broken", poll_s=0.002)
        else:
            transport.fail_with = boom
            waiter()
        assert len(woke) == 1 and isinstance(woke[0], LinkBrokenError)
        assert woke[0].__cause__ is boom
        assert robot.state == "broken" and not robot.armed
        for call in (robot.arm, lambda: robot.drive(0.1, 0.0), robot.read_config, robot.wait_feedback):
            with pytest.raises(RoverLinkError) as err:
                call()
            assert err.value.__cause__ is boom and "ValueError: a bug in a layer below" in str(err.value)
    finally:
        robot.close()
    assert robot.state == "closed"
    assert thread_tracebacks == []


def test_kinematics_of_the_wrong_type_is_refused_before_any_thread_starts(
    thread_tracebacks: list[threading.ExceptHookArgs],
) -> None:
    threads = set(threading.enumerate())
    with pytest.raises(RoverLinkError, match="kinematics"):
        Robot.connect("emu://diffdrive-tb6612?clock=real", kinematics=object())  # type: ignore[arg-type]
    assert set(threading.enumerate()) == threads and thread_tracebacks == []


@pytest.mark.parametrize("clock", ["real", "virtual"])
def test_a_port_that_disappears_while_driving_leaves_no_stale_armed_state(clock: str) -> None:
    transport = FailingTransport(open_transport(f"emu://diffdrive-tb6612?clock={clock}"))
    with Robot.connect(transport=transport) as robot:
        robot.arm()
        robot.drive(0.2, 0.0)
        assert robot.state == "armed"
        unplugged = TransportError("reading /dev/ttyACM0 failed: device disconnected", transport.url)
        transport.fail_with = unplugged
        with pytest.raises(TransportError):
            for _ in range(100):
                robot.drive(0.2, 0.0)
                robot.wait_feedback(timeout_s=2.0)
        assert robot.state == "broken" and not robot.armed and robot.failsafe is None
        with pytest.raises(TransportError):
            robot.drive(0.2, 0.0)
