"""A robot's port kept open: connect, watch, and connect again with backoff when the port is lost.

One thread owns the Robot's lifetime. It connects (retrying with a doubling delay while the port
is missing or the board silent), or starts from a robot already connected (`initial`), hands the
robot over (`on_connected`), then checks it ten times a second: a robot whose port failed (a
pulled USB adapter: TransportError) or whose session cannot go on is handed back (`on_lost`),
closed, and a new one connected the same way. Errors another try cannot fix (incompatible
firmware, a bad profile) end the thread and are kept in `fatal`. With `stats_period_s` it also
fetches the board's link counters (each fetch feeds the board's watchdog: `may_poll_board` says
when not to).

A board reset, a cut cable or a hung board keep the port open: the robot's session handles those
(it handshakes again by itself after a reset); they are `Supervisor`'s to report, not this
thread's to reconnect.
"""

from __future__ import annotations

import contextlib
import logging
import threading
import time
from collections.abc import Callable

from host_sdk.errors import ConnectTimeoutError, RobotClosedError, RoverLinkError, TransportError
from host_sdk.robot import Robot
from protocol.generated.messages import LinkStats

log = logging.getLogger("host_sdk.supervisor")

Connect = Callable[[], Robot]
UNUSABLE = ("broken", "incompatible", "closed")
"""Robot states a new connection is the only way out of."""
HEALTH_PERIOD_S = 0.1
"""How often the connection thread checks the port: how soon a lost port is noticed."""


class Connection:
    def __init__(
        self,
        connect: Connect,
        *,
        on_connected: Callable[[Robot], None],
        on_lost: Callable[[Robot, str], None],
        initial: Robot | None = None,
        delay_s: float = 0.5,
        delay_max_s: float = 5.0,
        stats_period_s: float | None = None,
        may_poll_board: Callable[[], bool] = lambda: True,
    ) -> None:
        self._connect = connect
        self._on_connected = on_connected
        self._on_lost = on_lost
        self._initial = initial
        self.delay_s = delay_s
        self.delay_max_s = delay_max_s
        self.stats_period_s = stats_period_s
        self._may_poll_board = may_poll_board
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._robot: Robot | None = None
        self._thread: threading.Thread | None = None
        self.state = "connecting"
        """connecting, connected, reconnecting, failed or closed."""
        self.error = ""
        self.attempts = 0
        """Failed attempts since the last success."""
        self.reconnects = 0
        self.fatal: RoverLinkError | None = None
        self.board: tuple[LinkStats, float] | None = None
        """The board's link counters and when they were read (host clock)."""
        self.ever_connected = False

    @property
    def robot(self) -> Robot | None:
        with self._lock:
            return self._robot

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="roverlink-connection", daemon=True)
        self._thread.start()

    def stop(self) -> Robot | None:
        """End the thread; returns the robot (still open) for the caller to stop, disarm and close."""
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=10.0)
        with self._lock:
            robot, self._robot = self._robot, None
        self.state = "closed"
        return robot

    def _run(self) -> None:
        delay = self.delay_s
        while not self._stop.is_set():
            try:
                robot = self._next_robot()
            except (TransportError, ConnectTimeoutError) as exc:
                self.attempts += 1
                self.error = str(exc)
                self.state = "reconnecting" if self.ever_connected else "connecting"
                if self.attempts == 1 or self.attempts % 10 == 0:
                    log.warning("connecting failed (attempt %d), retrying in %.1f s: %s", self.attempts, delay, exc)
                self._stop.wait(delay)
                delay = min(delay * 2, self.delay_max_s)
                continue
            except RoverLinkError as exc:
                self.fatal = exc
                self.error = str(exc)
                self.state = "failed"
                log.error("cannot connect: %s", exc)
                return
            delay = self.delay_s
            if not self._serve(robot):
                return

    def _next_robot(self) -> Robot:
        initial, self._initial = self._initial, None
        return initial if initial is not None else self._connect()

    def _serve(self, robot: Robot) -> bool:
        """Hand `robot` over and watch it; False once stop() was called."""
        if self.ever_connected:
            self.reconnects += 1
        self.ever_connected = True
        self.attempts = 0
        self.error = ""
        self.board = None
        try:
            self._on_connected(robot)
        except RoverLinkError as exc:
            log.warning("setting up the robot failed: %s", exc)
        with self._lock:
            self._robot = robot  # stop() takes it from here to stop, disarm and close it
        self.state = "connected"
        why = self._watch(robot)
        if why is None or self._stop.is_set():
            return False
        with self._lock:
            self._robot = None
        self.state = "reconnecting"
        self.error = why
        log.error("lost the connection: %s; reconnecting", why)
        self._on_lost(robot, why)
        with contextlib.suppress(RoverLinkError):
            robot.close()
        return True

    def _watch(self, robot: Robot) -> str | None:
        """Check the robot every HEALTH_PERIOD_S until the link breaks (returns why) or stop() (None).

        Waiting on this thread's own event, not on the robot's feedback, keeps it asleep between
        checks; a check that waits 1 ms for FEEDBACK raises at once when the port has failed."""
        next_stats = time.monotonic()
        while not self._stop.wait(HEALTH_PERIOD_S):
            # Only a robot that cannot go on is asked why (a short wait raises it): a board reset is
            # left to the robot's session, and a quiet board to whoever shows the link's health.
            if robot.state in UNUSABLE:
                try:
                    robot.wait_feedback(0.001)
                except RoverLinkError as exc:  # the port failed, or the session did (a reconnect tells which)
                    return str(exc)
                return f"{robot.url}: the robot is {robot.state}"
            now = time.monotonic()
            if self.stats_period_s is not None and now >= next_stats and self._may_poll_board():
                next_stats = now + self.stats_period_s
                try:
                    self.board = (robot.board_link_stats(), time.monotonic())
                except (TransportError, RobotClosedError) as exc:
                    return str(exc)
                except RoverLinkError:
                    pass  # no answer now (a cut, a reset): shown as stale counters
        return None
