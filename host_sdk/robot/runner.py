"""The runner: drives a sans-I/O Session over a Transport, and lets user threads wait on it.

Two kinds, one interface:

- `ThreadedRunner`: one I/O thread reads the port, feeds the session its bytes and the time, and
  writes what it wants sent (real ports, `emu://...?clock=real`).
- `InlineRunner`: no thread; a call that waits moves the emulator's virtual clock itself, on the
  waiting thread (`emu://...?clock=virtual`).

Either way one lock guards the session; waiting happens on a condition variable without it, and
user callbacks run with no lock held. If anything below fails (the port vanishes: TransportError;
anything else: LinkBrokenError chaining the cause), the runner marks the session broken at once,
wakes every waiter, and every later call raises that error.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from host_sdk.errors import (
    LinkBrokenError,
    RobotClosedError,
    RoverLinkError,
    SessionResetError,
    TransportError,
    UnsupportedError,
)
from host_sdk.session import Event, Request, Session
from host_sdk.transport import Transport
from protocol.codec.message import Message

IO_POLL_S = 0.05
"""Longest the I/O thread sleeps in a read when no timer is due sooner (bounds how late it sees close())."""
VIRTUAL_STEP_S = 0.001
"""How far one inline step moves the virtual clock while waiting (the session's timers need ~ms)."""
REOPEN_BUDGET_S = 5.0
"""Extra time a request waits for while the session is re-opening after a board reset."""

Dispatch = Callable[[list[Event]], None]


class Runner:
    """What both runners share: the lock, waiting, writing, failing, stopping."""

    def __init__(self, session: Session, transport: Transport, dispatch: Dispatch) -> None:
        self.session = session
        self.transport = transport
        self.lock = threading.RLock()
        self.cond = threading.Condition(self.lock)
        self._delivering = threading.RLock()
        self.closed = False
        self._dispatch = dispatch
        self._pending: list[Event] = []

    # == lifecycle ==================================================================================
    def start(self) -> None:
        """Begin the handshake (and start the I/O thread, if any)."""
        with self.lock:
            self.session.start(self.transport.clock())
            self.flush()

    def stop(self) -> None:
        """Stop running and close the port. Idempotent; waiters wake."""
        with self.lock:
            self.closed = True
            self.session.close()
            self.cond.notify_all()
        self._join()
        self.transport.close()

    def abandon(self) -> None:
        """The robot was dropped without close(): stop without waiting for anything."""
        self.closed = True
        self.transport.close()

    def _join(self) -> None:
        pass

    # == state ======================================================================================
    @property
    def error(self) -> RoverLinkError | None:
        """Why the robot cannot go on (incompatible firmware, a failed link), or None."""
        return self.session.error

    def broken(self) -> bool:
        """Closed, or failed: a waiter must stop waiting. Call with the lock held."""
        return self.closed or self.session.error is not None

    def check(self) -> None:
        """Raise if the robot cannot be used: RobotClosedError, or the error that broke it."""
        if self.closed:
            raise RobotClosedError(self.transport.url)
        error = self.session.error
        if error is not None:
            raise error

    # == doing ======================================================================================
    def flush(self) -> None:
        """Write what the session wants sent (lock held). A failing port breaks the robot."""
        data = self.session.outgoing()
        if data:
            try:
                self.transport.write(data)
            except Exception as exc:
                self.fail(exc)
                error = self.session.error
                if error is None or error is exc:
                    raise
                raise error from exc

    def fail(self, exc: BaseException) -> None:
        """Something below failed: mark the session broken and wake everyone (lock taken here)."""
        error = exc if isinstance(exc, TransportError) else LinkBrokenError(self.transport.url, exc)
        with self.lock:
            if self.closed or self.session.error is not None:
                return
            self.session.fail(error)
            self._pending.extend(self.session.take_events())
            self.cond.notify_all()

    def _step(self, data: bytes) -> None:
        """Lock held: feed the session, run its timers, send what it wants sent, collect events."""
        s = self.session
        now = self.transport.clock()
        if data:
            s.receive(data, now)
        s.poll(now)
        self.flush()
        events = s.take_events()
        if events:
            self._pending.extend(events)
        self.cond.notify_all()

    def _deliver(self) -> None:
        """Run the user's callbacks for what happened (never with the session's lock held), one
        thread at a time: on a virtual clock every waiting thread moves the emulator, and two that
        delivered at once handed a subscriber sample 9 before 8."""
        if not self._pending:
            return
        with self._delivering:  # reentrant: a callback may wait on the robot, and deliver in turn
            with self.lock:
                events, self._pending = self._pending, []
            self._dispatch(events)

    def wait(self, predicate: Callable[[], bool], timeout_s: float) -> bool:
        """Wait until `predicate()` (evaluated with the lock held) is true, the robot breaks or
        closes, or `timeout_s` passes on the session's clock. Returns `predicate()`."""
        raise NotImplementedError

    def request(self, msg: Message, *, report_reset: bool = True) -> Message:
        """Send a reliable request and wait for its answer; raises what the session or link says.

        A reset not yet reported is raised first (SessionResetError, once) unless `report_reset`
        is False (a DISARM: cleanup code must not trip on it). A request a reset fails reports it."""
        with self.lock:
            self.check()
            s = self.session
            error = s.take_reset() if report_reset else None
            if error is not None:
                raise error
            req: Request = s.submit(msg, self.transport.clock())
            self.flush()
            # The session fails the request itself; this bounds the wait, a reset's silence included.
            budget = req.budget_s + s.options.reset_silence_s + (0.0 if s.ready else REOPEN_BUDGET_S)
        self.wait(lambda: req.done or self.broken(), budget)
        with self.lock:
            if not req.done:
                s.cancel(req)
                self.check()
            if isinstance(req.error, SessionResetError):
                s.take_reset()  # this request reports the reset: no later call does again
            if req.error is not None:
                raise req.error
            assert req.reply is not None
            return req.reply


class ThreadedRunner(Runner):
    """The session runs on one I/O thread; user threads wait on the condition variable."""

    def __init__(self, session: Session, transport: Transport, dispatch: Dispatch) -> None:
        super().__init__(session, transport, dispatch)
        self._thread = threading.Thread(target=self._run, name=f"roverlink-io {transport.url}", daemon=True)

    def start(self) -> None:
        super().start()
        self._thread.start()

    def abandon(self) -> None:
        self.closed = True  # the thread sees it within IO_POLL_S and closes the port itself

    def _run(self) -> None:
        try:
            self._loop()
        except BaseException as exc:  # whatever it is, the robot must say so, not hang
            self.fail(exc)
        if self.closed:
            self.transport.close()
        self._deliver()

    def _loop(self) -> None:
        # One wake-up per burst of bytes: read, then under the lock feed the session, run its
        # timers and write; run the callbacks; then work out how long the next read may sleep.
        transport, session, lock = self.transport, self.session, self.lock
        with lock:
            now = transport.clock()
            timeout = min(IO_POLL_S, max(0.0005, session.next_deadline(now) - now))
        while True:
            data = transport.read(timeout)
            with lock:
                if self.closed or session.error is not None:
                    return
                self._step(data)
            if self._pending:
                self._deliver()
            # From after the callbacks: a ROS node's publishing takes a millisecond or more, and a
            # paced setpoint due meanwhile would otherwise go out that much late, every period.
            with lock:
                now = transport.clock()
                timeout = min(IO_POLL_S, max(0.0005, session.next_deadline(now) - now))

    def _join(self) -> None:
        thread = self._thread
        if thread.is_alive() and thread is not threading.current_thread():
            thread.join(timeout=2.0)

    def wait(self, predicate: Callable[[], bool], timeout_s: float) -> bool:
        if threading.current_thread() is self._thread:
            raise UnsupportedError(
                "a call that waits for the board (requests, arm, wait_feedback, sleep) cannot run in a callback: "
                "callbacks run on the I/O thread, which would have to answer it; hand the work to another thread"
            )
        deadline = time.monotonic() + timeout_s
        with self.cond:
            while not predicate():
                left = deadline - time.monotonic()
                if left <= 0 or self.broken():
                    return predicate()
                self.cond.wait(min(left, 0.1))
            return True


class InlineRunner(Runner):
    """No thread: waiting runs the virtual clock forward on the waiting thread."""

    def wait(self, predicate: Callable[[], bool], timeout_s: float) -> bool:
        transport, session = self.transport, self.session
        with self.lock:
            deadline = transport.clock() + timeout_s
        while True:
            with self.lock:
                if predicate():
                    return True
                now = transport.clock()
                if now >= deadline - 1e-9 or self.broken():
                    return predicate()
                step = min(deadline, session.next_deadline(now), now + VIRTUAL_STEP_S) - now
                try:
                    self._step(transport.read(max(step, 0.0002)))
                except Exception as exc:
                    if self.session.error is None:
                        self.fail(exc)
            self._deliver()


def runner_for(session: Session, transport: Transport, dispatch: Dispatch) -> Runner:
    """The runner a transport needs: inline on a virtual clock, else threaded."""
    cls = InlineRunner if transport.virtual else ThreadedRunner
    return cls(session, transport, dispatch)
