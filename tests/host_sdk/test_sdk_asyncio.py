"""AsyncRobot (host_sdk.aio) on the emulator's virtual clock and on its real clock: feedback in order
and none lost, driving, other tasks running while the robot is awaited, cancellation, typed errors.
(examples/async_server.py runs as documented in test_sdk_examples.py.)

The `robot`/`emulator` fixtures are the pytest plugin's (virtual clock); `AsyncRobot(robot)` wraps one.
"""

from __future__ import annotations

import asyncio
import json
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import pytest

from host_sdk import AsyncRobot, Robot
from host_sdk.aio import VIRTUAL_SLICE_S
from host_sdk.errors import (
    ArgumentTypeError,
    CommandRangeError,
    FeedbackTimeoutError,
    NackError,
    NotArmedError,
    RobotClosedError,
    SessionResetError,
)
from host_sdk.session import FeedbackSample

pytestmark = pytest.mark.asyncio

VIRTUAL = "emu://diffdrive-tb6612?clock=virtual"
REAL = "emu://diffdrive-tb6612?clock=real"


async def fetch(port: int, path: str = "/odometry") -> tuple[str, bytes]:
    """One HTTP GET over asyncio streams: (status line, body)."""
    reader, writer = await asyncio.open_connection("127.0.0.1", port)
    writer.write(f"GET {path} HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n".encode())
    await writer.drain()
    response = await reader.read()
    writer.close()
    head, _, body = response.partition(b"\r\n\r\n")
    return head.split(b"\r\n")[0].decode(), body


# -- the new user's pitfall ---------------------------------------------------------------------------
async def test_the_call_soon_threadsafe_bridge_starves_on_a_virtual_clock_and_async_robot_does_not(
    roverlink_robot: Robot,
) -> None:
    """Queuing on_feedback into the loop works on a real clock, but on a virtual one nothing moves
    time, so the loop waits for ever; AsyncRobot's awaits move it."""
    loop = asyncio.get_running_loop()
    queue: asyncio.Queue[FeedbackSample] = asyncio.Queue()
    roverlink_robot.on_feedback(lambda sample: loop.call_soon_threadsafe(queue.put_nowait, sample))
    start = roverlink_robot.now()
    with pytest.raises(asyncio.TimeoutError):  # the built-in TimeoutError from Python 3.11 on
        await asyncio.wait_for(queue.get(), 0.3)
    assert roverlink_robot.now() == start  # the emulator's time stood still

    bot = AsyncRobot(roverlink_robot)
    sample = await bot.wait_feedback()
    async for streamed in bot.feedback():
        assert streamed.index == sample.index + 1
        break
    assert roverlink_robot.now() > start
    assert (await queue.get()).index == sample.index  # and the bridge saw them too, now that time moves


# -- both clocks --------------------------------------------------------------------------------------
@pytest.mark.parametrize("url", [VIRTUAL, REAL], ids=["virtual", "real"])
async def test_connect_arm_drive_and_every_sample_in_order(url: str) -> None:
    async with AsyncRobot.connect(url, timeout_s=5.0) as robot:
        assert robot.virtual_clock == ("virtual" in url)
        assert robot.identity.robot_name and robot.config.max_wheel_speed_mm_s > 0
        await robot.arm()
        assert robot.armed
        robot.odometry.reset()
        seen: list[int] = []
        async for sample in robot.feedback():
            robot.drive(0.3, 0.0)
            seen.append(sample.index)
            if len(seen) == 40:  # 0.8 s at 50 Hz
                break
        robot.stop()
        await robot.sleep(0.2)
        assert seen == list(range(seen[0], seen[0] + 40))
        assert 0.1 < robot.odometry.pose.x_m < 0.4
        assert robot.stats.feedback_received >= 40
        sync = robot.sync
    assert sync.closed and robot.closed


@pytest.mark.parametrize("url", [VIRTUAL, REAL], ids=["virtual", "real"])
async def test_two_streams_in_two_tasks_each_get_every_sample_in_order(url: str) -> None:
    """On a virtual clock each waiting thread moves the emulator and runs the callbacks for what it
    made: two of them at once once delivered sample 9 before 8."""
    async with AsyncRobot.connect(url, timeout_s=5.0) as robot:

        async def collect() -> list[int]:
            seen: list[int] = []
            async for sample in robot.feedback():
                seen.append(sample.index)
                if len(seen) == 100:
                    break
            return seen

        for seen in await asyncio.gather(collect(), collect(), collect()):
            assert seen == list(range(seen[0], seen[0] + 100))


async def test_a_stream_goes_on_across_a_reset_and_leaves_it_to_the_driving_task() -> None:
    """The recovery pattern in one task, a feedback logger in another: the logger's stream does not
    take the reset (docs/sdk.md: "one reset, one error"), the driving task meets it and re-arms. On
    the real clock: on a virtual one the logger's waits carry the clock past the driver's renewals
    (docs/sdk.md, "Cancellation"), and the board's watchdog trips first."""
    async with AsyncRobot.connect(REAL + "&faults=reset@1", timeout_s=5.0) as robot:
        await robot.arm()
        resets = 0
        logged: list[int] = []

        async def log_feedback() -> None:
            async for sample in robot.feedback(timeout_s=3.0):
                logged.append(sample.index)

        logger = asyncio.create_task(log_feedback())
        start = robot.now()
        while robot.now() - start < 4.0:
            try:
                robot.drive(0.2, 0.0)
                await robot.sleep(0.05)
            except SessionResetError:
                resets += 1
                await robot.arm()
        assert not logger.done(), logger  # the stream neither raised nor ended
        logger.cancel()
        assert resets == 1 and robot.stats.resets_detected == 1 and len(logged) > 100


@pytest.mark.parametrize("url", [VIRTUAL, REAL], ids=["virtual", "real"])
async def test_other_tasks_run_while_the_robot_is_awaited(url: str) -> None:
    """An asyncio server answers while a task sleeps on the robot (virtual clock: the sleep is the
    emulator running, in a worker thread) and while another awaits feedback."""
    async with AsyncRobot.connect(url) as robot:

        async def answer(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
            await reader.readuntil(b"\r\n\r\n")
            body = json.dumps({"x_m": robot.odometry.pose.x_m}).encode()
            writer.write(b"HTTP/1.1 200 OK\r\nContent-Length: %d\r\n\r\n%s" % (len(body), body))
            await writer.drain()
            writer.close()

        async with await asyncio.start_server(answer, "127.0.0.1", 0) as server:
            port = server.sockets[0].getsockname()[1]
            start = robot.now()
            sleeping = asyncio.create_task(robot.sleep(1000.0))
            waiting = asyncio.create_task(robot.wait_feedback(timeout_s=5.0))
            status, body = await fetch(port)
            assert status.endswith("200 OK") and "x_m" in json.loads(body)
            assert not sleeping.done()
            assert isinstance(await waiting, FeedbackSample)
            sleeping.cancel()
            with pytest.raises(asyncio.CancelledError):
                await sleeping
            assert robot.now() - start < 1000.0
        assert isinstance(await robot.wait_feedback(), FeedbackSample)


# -- the feedback stream ------------------------------------------------------------------------------
async def test_a_slow_consumer_loses_nothing_within_the_bound_and_the_oldest_beyond_it(roverlink_robot: Robot) -> None:
    bot = AsyncRobot(roverlink_robot)
    async with bot.feedback() as stream:
        first = await anext(stream)
        await bot.sleep(0.5)  # ~25 samples arrive meanwhile: all buffered
        got = [first] + [await anext(stream) for _ in range(30)]
        assert [s.index for s in got] == list(range(first.index, first.index + 31))
        assert stream.dropped == 0
    assert stream.closed

    async with bot.feedback(maxsize=5) as small:
        head = await anext(small)
        await bot.sleep(0.5)
        rest = [await anext(small) for _ in range(5)]
        assert small.dropped >= 15
        assert rest[0].index - head.index > 1  # the gap shows where samples were dropped
        assert [s.index for s in rest] == list(range(rest[0].index, rest[0].index + 5))  # the newest five


async def test_the_stream_ends_when_the_robot_closes(roverlink_robot: Robot) -> None:
    bot = AsyncRobot(roverlink_robot)
    seen = 0
    async for _ in bot.feedback():
        seen += 1
        if seen == 3:
            await bot.aclose()
    assert seen == 3


async def test_a_stream_left_by_break_unsubscribes(roverlink_robot: Robot) -> None:
    bot = AsyncRobot(roverlink_robot)
    subscribers = len(roverlink_robot._link.callbacks.feedback)
    async for _ in bot.feedback():
        break
    assert len(roverlink_robot._link.callbacks.feedback) == subscribers  # collected at once: its finalizer unsubscribed


# -- cancellation -------------------------------------------------------------------------------------
async def test_cancelling_a_task_awaiting_feedback_leaves_the_robot_usable(
    roverlink_robot: Robot, roverlink_emulator: Any
) -> None:
    bot = AsyncRobot(roverlink_robot)
    await bot.arm()
    roverlink_emulator.cut_link()  # no FEEDBACK comes: the tasks are surely waiting when cancelled
    waiting = asyncio.create_task(bot.wait_feedback(timeout_s=5.0))
    stream = bot.feedback()
    iterating = asyncio.create_task(anext(stream))
    await asyncio.sleep(0)
    waiting.cancel()
    iterating.cancel()
    for task in (waiting, iterating):
        with pytest.raises(asyncio.CancelledError):
            await task
    roverlink_emulator.restore_link()
    await bot.arm()  # the robot (which failed safe meanwhile) answers requests again
    for _ in range(25):
        bot.drive(0.3, 0.0)
        await bot.sleep(0.02)
    assert bot.odometry.pose.x_m > 0.05
    sample = await bot.wait_feedback()
    assert (await anext(stream)).index > 0 and sample.index > 0  # the stream goes on too
    await stream.aclose()


async def test_cancelling_a_virtual_sleep_stops_the_emulator_within_a_slice(roverlink_robot: Robot) -> None:
    # One worker thread: a call queued behind the cancelled sleep's last slice runs when it has ended.
    asyncio.get_running_loop().set_default_executor(ThreadPoolExecutor(max_workers=1))
    bot = AsyncRobot(roverlink_robot)
    start = roverlink_robot.now()
    sleeping = asyncio.create_task(bot.sleep(1000.0))
    await bot.wait_feedback()
    sleeping.cancel()
    with pytest.raises(asyncio.CancelledError):
        await sleeping
    cancelled = roverlink_robot.now()
    after_last_slice = await asyncio.to_thread(roverlink_robot.now)
    assert cancelled - start < 1.0
    assert after_last_slice - cancelled <= VIRTUAL_SLICE_S + 1e-6
    assert await asyncio.to_thread(roverlink_robot.now) == after_last_slice  # nothing moves time any more


# -- errors -------------------------------------------------------------------------------------------
async def test_errors_are_the_robots_own(roverlink_robot: Robot) -> None:
    bot = AsyncRobot(roverlink_robot)
    with pytest.raises(NotArmedError):
        bot.drive(0.1, 0.0)
    with pytest.raises(CommandRangeError, match="bogus"):
        await bot.set_config(bogus=1)
    with pytest.raises(CommandRangeError, match="seconds"):
        await bot.sleep(-1.0)
    with pytest.raises(CommandRangeError, match="maxsize"):
        bot.feedback(maxsize=0)
    with pytest.raises(ArgumentTypeError, match="timeout_s"):
        bot.feedback(timeout_s="soon")  # type: ignore[arg-type]
    with pytest.raises(ArgumentTypeError, match="robot"):
        AsyncRobot("emu://")  # type: ignore[arg-type]
    await bot.arm()
    with pytest.raises(NackError) as nack:
        await bot.save_config()
    assert nack.value.reason.name == "ARMED"
    assert (await bot.set_pid(kp=1.5)).kp == pytest.approx(1.5, abs=0.01)
    await bot.disarm()
    await bot.aclose()
    with pytest.raises(RobotClosedError):
        await bot.wait_feedback()
    with pytest.raises(RobotClosedError):
        await bot.sleep(0.1)
    with pytest.raises(RobotClosedError):  # not a stream that silently yields nothing
        bot.feedback()
    with pytest.raises(AttributeError, match=r"armed is read-only.*disarm"):
        bot.armed = False  # type: ignore[assignment]


async def test_connect_errors_and_feedback_timeouts_are_typed() -> None:
    with pytest.raises(CommandRangeError, match="watchdog_s"):
        await AsyncRobot.connect(VIRTUAL, watchdog_s=99.0)
    robot = await AsyncRobot.connect(VIRTUAL)
    robot.sync.emulator.cut_link()
    with pytest.raises(FeedbackTimeoutError):
        await robot.wait_feedback(timeout_s=0.2)
    with pytest.raises(FeedbackTimeoutError):
        async for _ in robot.feedback(timeout_s=0.2):
            pass
    await robot.aclose()
