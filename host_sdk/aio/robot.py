"""`AsyncRobot`: the Robot for asyncio programs, on a real clock and on the emulator's virtual clock.

    from host_sdk import AsyncRobot

    async with AsyncRobot.connect("emu://?clock=virtual") as robot:
        await robot.arm()
        async for sample in robot.feedback():
            robot.drive(0.2, 0.0)
            if robot.odometry.pose.x_m > 1.0:
                break
        robot.stop()

It holds a `Robot` (`robot.sync`) and adds no session logic of its own. Calls that wait for the
board (connect, arm, requests, wait_feedback, a virtual clock's sleep) run the Robot's call in a
worker thread, so the event loop goes on serving other tasks meanwhile; on a virtual clock that
waiting thread is what moves the emulator's time, exactly as `Robot.sleep` does. Calls that only
send (drive, stop) or read state (odometry, identity, config, stats) are the Robot's own, unchanged.

Cancelling an awaited call cancels the await, not what the thread is doing: a request may still be
applied, and a `wait_feedback` ends by itself at the next sample (or its timeout). The robot stays
usable either way. A virtual clock's `sleep` moves time in slices of VIRTUAL_SLICE_S, so a
cancelled one stops within a slice.
"""

from __future__ import annotations

import asyncio
import functools
import inspect
from collections.abc import Callable, Coroutine, Generator
from types import TracebackType
from typing import Any, Concatenate, Generic, NoReturn, ParamSpec, TypeVar, overload

from host_sdk import checks
from host_sdk.aio.feedback import DEFAULT_MAXSIZE, FeedbackStream
from host_sdk.errors import RobotClosedError
from host_sdk.robot import OdometryView, Robot
from host_sdk.session import RobotConfig

P = ParamSpec("P")
T = TypeVar("T")

VIRTUAL_SLICE_S = 0.05
"""Longest stretch of virtual time one worker-thread hop of `AsyncRobot.sleep` runs the emulator."""


def _in_thread(
    method: Callable[Concatenate[Robot, P], T],
) -> Callable[Concatenate[AsyncRobot, P], Coroutine[Any, Any, T]]:
    """Robot's `method` as a coroutine method: the call waits in a worker thread, not on the loop."""

    @functools.wraps(method)
    async def call(self: AsyncRobot, /, *args: P.args, **kwargs: P.kwargs) -> T:
        return await asyncio.to_thread(method, self.sync, *args, **kwargs)

    return call


def _same(method: Callable[Concatenate[Robot, P], T]) -> Callable[Concatenate[AsyncRobot, P], T]:
    """Robot's `method` as it is: it only sends (or reads), so it returns at once."""

    @functools.wraps(method)
    def call(self: AsyncRobot, /, *args: P.args, **kwargs: P.kwargs) -> T:
        return method(self.sync, *args, **kwargs)

    return call


class _Read(Generic[T]):
    """A property of Robot, read through `AsyncRobot.sync` (read-only; it never waits)."""

    def __init__(self, prop: Callable[[Robot], T]) -> None:
        # mypy sees a property on the class as its getter; at run time it is the property itself
        self._get: Callable[[Robot], T] = getattr(prop, "fget", prop)
        self.__doc__ = prop.__doc__

    @overload
    def __get__(self, robot: None, owner: type[Any]) -> _Read[T]: ...
    @overload
    def __get__(self, robot: AsyncRobot, owner: type[Any]) -> T: ...
    def __get__(self, robot: AsyncRobot | None, owner: type[Any]) -> T | _Read[T]:
        return self if robot is None else self._get(robot.sync)

    def __set_name__(self, owner: type[Any], name: str) -> None:
        self._name = name

    def __set__(self, robot: AsyncRobot, value: NoReturn) -> None:
        # None of these can be set on the Robot either: the calls that change them are named.
        raise AttributeError(
            f"{self._name} is read-only: the robot's state, changed by its calls (arm, disarm, set_config, close...)"
        )


class Connecting:
    """What `AsyncRobot.connect(...)` returns: `await` it for the robot, or `async with` it to have
    the robot closed at the end of the block."""

    def __init__(self, open_robot: Callable[[], Robot]) -> None:
        self._open_robot = open_robot
        self._robot: AsyncRobot | None = None

    def __await__(self) -> Generator[Any, None, AsyncRobot]:
        return self._connect().__await__()

    async def _connect(self) -> AsyncRobot:
        opening = asyncio.get_running_loop().run_in_executor(None, self._open_robot)
        try:
            return AsyncRobot(await asyncio.shield(opening))
        except asyncio.CancelledError:
            opening.add_done_callback(_close_opened)  # the connect goes on in its thread: close what it opens
            raise

    async def __aenter__(self) -> AsyncRobot:
        self._robot = await self._connect()
        return self._robot

    async def __aexit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        if self._robot is not None:
            await self._robot.aclose()


def _close_opened(opening: asyncio.Future[Robot]) -> None:
    if not opening.cancelled() and opening.exception() is None:
        opening.result().close()


def _connector(connect: Callable[P, Robot]) -> Callable[P, Connecting]:
    """`Robot.connect` (same arguments, same checks and errors) as an awaitable / async context."""

    @functools.wraps(connect)
    def start(*args: P.args, **kwargs: P.kwargs) -> Connecting:
        return Connecting(functools.partial(connect, *args, **kwargs))

    start.__qualname__ = "AsyncRobot.connect"
    start.__signature__ = inspect.signature(connect).replace(return_annotation="Connecting")  # type: ignore[attr-defined]
    start.__doc__ = (
        "`Robot.connect`'s arguments; `async with AsyncRobot.connect(url, ...) as robot:` or\n"
        "`robot = await AsyncRobot.connect(url, ...)`. The handshake runs in a worker thread.\n\n"
        + (connect.__doc__ or "")
    )
    return start


class AsyncRobot:
    """A connected robot for asyncio code; see the module docstring and docs/sdk.md ("asyncio").

    Make one with `AsyncRobot.connect(url, ...)`, or wrap a connected Robot: `AsyncRobot(robot)`
    (closing the AsyncRobot closes that Robot). Errors are the Robot's, unchanged."""

    connect = staticmethod(_connector(Robot.connect))

    def __init__(self, robot: Robot) -> None:
        self.sync: Robot = checks.instance("robot", robot, Robot, "a connected host_sdk.Robot")
        """The Robot underneath: every synchronous call and callback (`robot.sync.on_reset(...)`)."""

    # == calls that wait for the board: in a worker thread ========================================
    arm = _in_thread(Robot.arm)
    disarm = _in_thread(Robot.disarm)
    wait_feedback = _in_thread(Robot.wait_feedback)
    read_config = _in_thread(Robot.read_config)
    pid = _in_thread(Robot.pid)
    set_pid = _in_thread(Robot.set_pid)
    save_config = _in_thread(Robot.save_config)
    board_link_stats = _in_thread(Robot.board_link_stats)
    set_lights = _in_thread(Robot.set_lights)
    lights = _in_thread(Robot.lights)

    async def set_config(self, **changes: Any) -> RobotConfig:
        """Robot.set_config (change CONFIG fields, read back) in a worker thread."""
        return await asyncio.to_thread(self.sync.set_config, **changes)

    # == calls that only send: at once, as on Robot ================================================
    # (with auto_rearm=True a drive call after a reset re-arms first: one round trip, on the loop)
    drive = _same(Robot.drive)
    set_wheel_speeds = _same(Robot.set_wheel_speeds)
    drive_ackermann = _same(Robot.drive_ackermann)
    stop = _same(Robot.stop)
    now = _same(Robot.now)

    async def sleep(self, seconds: float) -> None:
        """Wait `seconds` on the robot's clock, letting other tasks run. On a virtual clock this moves
        the emulator's time (as Robot.sleep does, in a worker thread); otherwise it is asyncio.sleep."""
        duration = checks.seconds("seconds", seconds, zero=True)
        robot = self.sync
        if robot.closed:
            raise RobotClosedError(robot.url)
        if not robot.virtual_clock:
            await asyncio.sleep(duration)
            return
        await asyncio.sleep(0)  # a sleep always lets other tasks run, even sleep(0)
        end = robot.now() + duration
        while (left := end - robot.now()) > 1e-9:
            before = robot.now()
            await asyncio.to_thread(robot.sleep, min(left, VIRTUAL_SLICE_S))
            if robot.now() <= before:
                return  # the robot closed or broke: time stands still, as after Robot.sleep

    def feedback(self, *, timeout_s: float = 1.0, maxsize: int = DEFAULT_MAXSIZE) -> FeedbackStream:
        """Every FEEDBACK from now on, in order: `async for sample in robot.feedback():`.

        None is lost while the consumer keeps up; `maxsize` samples are buffered, and when full
        the oldest is dropped (`stream.dropped` counts them). Raises FeedbackTimeoutError when
        no sample arrives within `timeout_s`; ends when the robot is closed (RobotClosedError if it
        is closed already). See FeedbackStream."""
        if self.sync.closed:
            raise RobotClosedError(self.sync.url)
        return FeedbackStream(self.sync, timeout_s=timeout_s, maxsize=maxsize)

    # == state (the Robot's, read at once) =========================================================
    @property
    def odometry(self) -> OdometryView:
        """Pose and body velocities from the wheel encoders; `odometry.reset()` sets the origin."""
        return self.sync.odometry

    identity = _Read(Robot.identity)
    config = _Read(Robot.config)
    stats = _Read(Robot.stats)
    kinematics = _Read(Robot.kinematics)
    state = _Read(Robot.state)
    armed = _Read(Robot.armed)
    url = _Read(Robot.url)
    virtual_clock = _Read(Robot.virtual_clock)
    closed = _Read(Robot.closed)

    # == closing ===================================================================================
    async def aclose(self) -> None:
        """Disarm (best effort), stop and release the port, in a worker thread. Idempotent."""
        await asyncio.to_thread(self.sync.close)

    async def __aenter__(self) -> AsyncRobot:
        return self

    async def __aexit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        await self.aclose()

    def __repr__(self) -> str:
        return f"<AsyncRobot {self.sync.url} {self.sync.state}>"
