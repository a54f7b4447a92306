"""`AsyncRobot.feedback()`: every FeedbackSample, in order, as an async iterator.

The robot's `on_feedback` callback (on the I/O thread, or on a virtual clock on whichever thread
is waiting) hands each sample to the event loop with `call_soon_threadsafe`; the loop keeps them
in a bounded buffer. When the buffer is empty the iterator waits with `Robot.wait_feedback` in a
worker thread: that is what moves a virtual clock, and it raises the robot's own errors.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import weakref
from collections import deque
from types import TracebackType

from host_sdk import checks
from host_sdk.errors import FeedbackTimeoutError, RobotClosedError
from host_sdk.robot import Robot
from host_sdk.session import FeedbackSample

log = logging.getLogger("host_sdk")

DEFAULT_MAXSIZE = 256
"""Samples a FeedbackStream holds for a slow consumer (about 5 s at the default 50 Hz)."""
MAX_MAXSIZE = 1_000_000


class FeedbackStream:
    """Every FeedbackSample from the moment it was made, in order: `async for sample in stream`.

    None is lost while the consumer keeps up. The buffer holds `maxsize` samples; when it is full
    the oldest is dropped to make room (a control loop wants the newest), `dropped` counts them,
    a warning is logged once, and the gap shows in `FeedbackSample.index` (consecutive otherwise).
    Raises FeedbackTimeoutError when no sample comes within `timeout_s` (the robot's clock), the
    link's own error when it breaks; ends when the robot is closed or `aclose()` is called. It goes
    on across a board reset, which it leaves to the robot's next drive call, wait, arm or request.
    """

    def __init__(self, robot: Robot, *, timeout_s: float = 1.0, maxsize: int = DEFAULT_MAXSIZE) -> None:
        self._timeout = checks.seconds("timeout_s", timeout_s)
        self.maxsize = checks.integer("maxsize", maxsize, 1, MAX_MAXSIZE, what="a number of samples")
        self._robot = robot
        self._loop = asyncio.get_running_loop()
        self._buffer: deque[FeedbackSample] = deque()
        self._arrived = asyncio.Event()
        self._closed = False
        self.dropped = 0
        """Samples dropped because the buffer was full."""
        # The callback holds the stream weakly: a stream dropped unfinished (a `break` out of
        # `async for`) is collected, and the finalizer unsubscribes it.
        ref = weakref.ref(self)
        loop = self._loop

        def deliver(sample: FeedbackSample) -> None:
            stream = ref()
            if stream is None or loop.is_closed():
                return
            with contextlib.suppress(RuntimeError):  # the loop closed just now: nobody listens any more
                loop.call_soon_threadsafe(stream._put, sample)

        self._unsubscribe = weakref.finalize(self, robot.on_feedback(deliver))

    @property
    def closed(self) -> bool:
        return self._closed

    def _put(self, sample: FeedbackSample) -> None:
        """On the loop: buffer one sample, dropping the oldest when full."""
        if self._closed:
            return
        if len(self._buffer) >= self.maxsize:
            self._buffer.popleft()
            if not self.dropped:
                log.warning("a feedback stream fell %d samples behind: dropping the oldest", self.maxsize)
            self.dropped += 1
        self._buffer.append(sample)
        self._arrived.set()

    def __aiter__(self) -> FeedbackStream:
        return self

    async def __anext__(self) -> FeedbackSample:
        if not self._buffer and not self._closed:
            try:
                # Waits for (and on a virtual clock runs the emulator up to) the next sample. As
                # feedback_stream, it goes on across a reset and leaves it to the robot's next call.
                await asyncio.to_thread(self._robot._next_feedback, self._timeout, False)
            except RobotClosedError:
                self._finish()
            await self._delivered()
        if self._buffer:
            return self._buffer.popleft()
        raise StopAsyncIteration

    async def _delivered(self) -> None:
        """Wait for the sample `wait_feedback` saw to reach the buffer. On a virtual clock it is
        there already; on a real one the I/O thread runs the callbacks just after it wakes waiters."""
        try:
            await asyncio.wait_for(self._buffered(), self._timeout)
        except asyncio.TimeoutError:  # not the built-in TimeoutError before Python 3.11
            raise FeedbackTimeoutError(self._timeout) from None

    async def _buffered(self) -> None:
        while not self._buffer and not self._closed:
            self._arrived.clear()
            await self._arrived.wait()

    def _finish(self) -> None:
        """Take no more samples; those buffered are still handed out, then the iteration ends."""
        self._closed = True
        self._unsubscribe()
        self._arrived.set()

    def close(self) -> None:
        """Stop listening and drop what is buffered: the iteration ends. Idempotent."""
        self._finish()
        self._buffer.clear()

    async def aclose(self) -> None:
        self.close()

    async def __aenter__(self) -> FeedbackStream:
        return self

    async def __aexit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()

    def __repr__(self) -> str:
        state = "closed" if self._closed else f"{len(self._buffer)}/{self.maxsize} buffered"
        return f"<FeedbackStream {state}, {self.dropped} dropped>"
