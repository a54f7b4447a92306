"""`Supervisor`: a robot program that rides through the robot's failures.

    with Supervisor.connect("/dev/ttyACM0", profile="picar", clamp=True) as sup:
        sup.arm()                               # False (and a refusal in health) if the board does not answer
        while True:
            health = sup.health()               # link up / lost since T / reconnecting; failsafe; last reset
            if health.armed:
                sup.drive(0.2, 0.0)             # False when it could not (the error is state, not an exception)
            sup.sleep(0.05)

It owns the robot's lifetime: the board's failures become state a program shows (`Health`), never
exceptions that end it. An ARM with no answer, one the board refuses, a board reset, a FEEDBACK
silence (a cut cable, a hung board), a failsafe: each is recorded with its time and what to do.
A lost port (a USB adapter pulled out) is opened again with backoff and the board handshaken
again (`Connection`; `Supervisor.connect`, or `reconnect=True` for a robot connected by URL), the
odometry carried on. It never arms by itself: arming is the program's call (`arm`), made again
after every failsafe, reset or lost link. `Health.halts` grows each time the robot stops being
armed and reachable, so whatever drives by itself (following) knows to stop and clear its
command: arming again never drives off.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
import queue
import threading
import time
from collections import deque
from collections.abc import Callable
from typing import Any

from host_sdk import checks
from host_sdk.errors import (
    FailsafeError,
    FeedbackTimeoutError,
    LinkBrokenError,
    NackError,
    NotArmedError,
    RequestTimeoutError,
    RobotClosedError,
    RoverLinkError,
    SessionResetError,
    TransportError,
    UnsupportedError,
)
from host_sdk.pose import Pose
from host_sdk.robot import Robot
from host_sdk.supervisor.connection import UNUSABLE, Connection
from host_sdk.supervisor.health import (
    LINK_CLOSED,
    LINK_LOST,
    LINK_RECONNECTING,
    LINK_UP,
    BoardReset,
    Health,
    Refusal,
)

log = logging.getLogger("host_sdk.supervisor")

LOST_AFTER_S = 0.5
"""FEEDBACK silent this long (or three feedback periods, if longer) means the link is lost."""
KEEP_REFUSALS = 8
BOARD_FAILURES = (
    RequestTimeoutError,
    NackError,
    SessionResetError,
    NotArmedError,
    FeedbackTimeoutError,
    TransportError,
    LinkBrokenError,
    RobotClosedError,
)
"""What the board, the link or the port can make a call raise: state, not the program's end."""


class Supervisor:
    """Watches `robot` (module docstring). `reconnect`: open the port again when it is lost (a
    robot connected by URL only); `lost_after_s`: how long a FEEDBACK silence may last before the
    link counts as lost (default LOST_AFTER_S, at least three feedback periods)."""

    def __init__(
        self,
        robot: Robot,
        *,
        reconnect: bool = False,
        lost_after_s: float | None = None,
        delay_s: float = 0.5,
        delay_max_s: float = 5.0,
    ) -> None:
        reconnect = checks.flag("reconnect", reconnect)
        self._lost_after = checks.optional(checks.seconds, "lost_after_s", lost_after_s)
        delay_s = checks.seconds("delay_s", delay_s)
        delay_max_s = checks.seconds("delay_max_s", delay_max_s)
        self._lock = threading.RLock()
        self._robot = robot
        self._ids = itertools.count(1)
        self._refusals: deque[Refusal] = deque(maxlen=KEEP_REFUSALS)
        self._reset: BoardReset | None = None
        self._halts = 0
        self._halt_why = ""
        self._since: tuple[float, float] | None = None
        """(robot clock, wall) when the link went down."""
        self._was_up = True
        self._was_armed = robot.armed
        self._busy: str | None = None
        self._port_error = ""
        self._pose: Pose | None = None
        self._closed = False
        self._jobs: queue.SimpleQueue[tuple[str, Callable[[], object]] | None] = queue.SimpleQueue()
        self._worker: threading.Thread | None = None
        self._watch(robot)
        self._connection: Connection | None = None
        if reconnect:
            if not robot.can_reopen:
                raise UnsupportedError(
                    f"reconnect=True needs a robot connected by URL; {robot.url} was "
                    "connected over a transport it was given"
                )
            self._connection = Connection(
                robot.reopen,
                initial=robot,
                on_connected=self._connected,
                on_lost=self._lost,
                delay_s=delay_s,
                delay_max_s=delay_max_s,
            )
            self._connection.start()

    @classmethod
    def connect(
        cls,
        url: str,
        *,
        reconnect: bool = True,
        lost_after_s: float | None = None,
        delay_s: float = 0.5,
        delay_max_s: float = 5.0,
        **options: Any,
    ) -> Supervisor:
        """`Robot.connect(url, **options)` (its errors: the first connection must succeed), supervised;
        with `reconnect` (the default) the port is opened again the same way whenever it is lost,
        after `delay_s`, doubling up to `delay_max_s` between tries."""
        robot = Robot.connect(url, **options)
        return cls(robot, reconnect=reconnect, lost_after_s=lost_after_s, delay_s=delay_s, delay_max_s=delay_max_s)

    # == the robot ==================================================================================
    @property
    def robot(self) -> Robot:
        """The robot now (another object after the port was lost and opened again)."""
        with self._lock:
            return self._robot

    @property
    def reconnects(self) -> bool:
        return self._connection is not None

    def now(self) -> float:
        return self.robot.now()

    def sleep(self, seconds: float) -> None:
        """`Robot.sleep` (wall or virtual clock); while the port is gone, the wall clock's."""
        robot = self.robot
        if robot.state not in UNUSABLE:
            with contextlib.suppress(RobotClosedError):
                robot.sleep(seconds)
                return
        time.sleep(seconds)  # a lost port: only ever on a real clock

    # == what it is doing ===========================================================================
    def health(self) -> Health:
        """A snapshot, computed now (it also notes the link going down and coming back)."""
        with self._lock:
            robot = self._robot
            now = robot.now()
            link = self._link(robot)
            armed = link == LINK_UP and robot.armed
            failsafe = robot.failsafe
            if link != LINK_UP and self._was_up:
                self._since = (now, time.time())
                self._halt("link lost" if link == LINK_LOST else "port lost")
            elif link == LINK_UP and not self._was_up:
                self._since = None
            if self._was_armed and not armed and link == LINK_UP:
                self._halt(f"failsafe {failsafe.name}" if failsafe is not None else "disarmed")
            self._was_up, self._was_armed = link == LINK_UP, armed
            conn = self._connection
            since = self._since
            return Health(
                link=link,
                since_s=None if since is None else since[0],
                since_wall=None if since is None else since[1],
                now_s=now,
                armed=armed,
                state=robot.state,
                failsafe=None if failsafe is None else failsafe.name,
                reset=self._reset,
                refusals=tuple(self._refusals),
                busy=self._busy,
                halts=self._halts,
                halt_why=self._halt_why,
                port_error=(conn.error if conn is not None and conn.error else "") or self._port_error,
                attempts=0 if conn is None else conn.attempts,
                url=robot.url,
            )

    def _link(self, robot: Robot) -> str:
        state = robot.state
        if state in UNUSABLE:
            if self._closed:
                return LINK_CLOSED
            conn = self._connection
            if conn is not None and conn.fatal is None:
                return LINK_RECONNECTING
            if not self._port_error:
                self._port_error = _why_unusable(robot)
            return LINK_LOST
        age = robot.feedback_age_s
        if age is None:  # connected, no FEEDBACK yet
            return LINK_UP
        return LINK_UP if age <= self._lost_after_s(robot) else LINK_LOST

    def _lost_after_s(self, robot: Robot) -> float:
        if self._lost_after is not None:
            return self._lost_after
        try:
            hz = robot.identity.feedback_hz
        except RoverLinkError:
            hz = 0
        return max(LOST_AFTER_S, 3.0 / hz) if hz else LOST_AFTER_S

    def _halt(self, why: str) -> None:
        with self._lock:
            self._halts += 1
            self._halt_why = why

    def dismiss(self, refusal_id: int) -> None:
        """Forget a refusal (the person has read it); an id no longer kept is ignored."""
        checks.integer("refusal_id", refusal_id, 0, 2**63, what="a Refusal's id")
        with self._lock:
            self._refusals = deque((r for r in self._refusals if r.id != refusal_id), maxlen=KEEP_REFUSALS)

    def _refuse(self, what: str, error: BaseException | str) -> Refusal:
        refusal = Refusal(next(self._ids), what, str(error), time.time())
        with self._lock:
            self._refusals.append(refusal)
        log.warning("%s: %s", what, error)
        return refusal

    # == arming and driving ========================================================================
    def arm(self, timeout_s: float = 2.0) -> bool:
        """Arm now (waits for the answer: while the link is down, its tries and a reset's silence);
        False when it could not, with a refusal in `health()`. A board reset not yet reported is
        taken as seen: the new boot is armed. Tried even while the link looks down: a busy host's
        FEEDBACK can pause longer than `lost_after_s` while the board still hears it."""
        for _ in range(2):
            robot = self.robot
            try:
                robot.arm(timeout_s)
            except SessionResetError as exc:  # seen on the page already; arm the new boot
                self._note_reset(exc)
                continue
            except BOARD_FAILURES as exc:
                self._refuse("ARM", exc)
                return False
            with self._lock:
                self._reset = None
                self._was_armed = True
            return True
        self._refuse("ARM", "the board was reset twice while arming: arm again")
        return False

    def disarm(self) -> bool:
        """Disarm now; False when the board did not answer (it fails safe by itself: nothing is sent)."""
        try:
            self.robot.disarm()
        except BOARD_FAILURES as exc:
            self._refuse("DISARM", exc)
            return False
        return True

    def arm_soon(self) -> None:
        """`arm()` on the supervisor's own thread: the caller's loop goes on meanwhile."""
        self._later("arming", self.arm)

    def stop(self) -> None:
        """STOP: zero speed now and nothing repeated, then DISARM on the supervisor's own thread."""
        with contextlib.suppress(*BOARD_FAILURES):
            self.robot.stop()
        self._halt("stopped")
        self._later("disarming", self.disarm)

    def drive(self, linear_m_s: float, angular_rad_s: float, *, clamp: bool | None = None) -> bool:
        """`Robot.drive`; False (the reason in `health()`) when the robot cannot drive now. Only
        argument errors raise."""
        try:
            self.robot.drive(linear_m_s, angular_rad_s, clamp=clamp)
        except SessionResetError as exc:
            self._note_reset(exc)
            return False
        except FailsafeError as exc:
            self._halt(f"failsafe {getattr(exc.reason, 'name', exc.reason)}")
            return False
        except NotArmedError:
            self._halt("not armed")
            return False
        except BOARD_FAILURES:
            return False  # the link's state says why
        return True

    def stop_driving(self) -> None:
        """Zero speed now (nothing if not armed); never raises for the board's failures."""
        with contextlib.suppress(*BOARD_FAILURES):
            self.robot.stop()

    def _later(self, what: str, job: Callable[[], object]) -> None:
        with self._lock:
            if self._closed:
                return
            if self._worker is None:
                self._worker = threading.Thread(target=self._work, name="roverlink-supervisor", daemon=True)
                self._worker.start()
        self._jobs.put((what, job))

    def _work(self) -> None:
        while (item := self._jobs.get()) is not None:
            what, job = item
            with self._lock:
                self._busy = what
            try:
                job()
            except Exception:  # a bug in a job must not end the thread that arms and stops
                log.exception("%s failed", what)
            finally:
                with self._lock:
                    self._busy = None

    # == the robot's events (its I/O thread; the connection's thread) ================================
    def _watch(self, robot: Robot) -> None:
        robot.on_reset(self._note_reset)
        robot.on_failsafe(lambda reason: self._halt(f"failsafe {reason.name}"))

    def _note_reset(self, error: SessionResetError) -> None:
        robot = self._robot
        with self._lock:
            known = self._reset
            if known is None or known.old_boot_id != error.old_boot_id:
                self._reset = BoardReset(robot.now(), time.time(), error.old_boot_id, error.new_boot_id)
            elif known.new_boot_id is None and error.new_boot_id is not None:
                self._reset = BoardReset(known.at_s, known.wall, known.old_boot_id, error.new_boot_id)
            self._halt("board reset")

    def _lost(self, robot: Robot, why: str) -> None:
        with self._lock:
            self._port_error = why
            self._halt("port lost")
        with contextlib.suppress(RoverLinkError):
            self._pose = robot.odometry.pose  # carried on by the next robot

    def _connected(self, robot: Robot) -> None:
        with self._lock:
            if robot is self._robot:
                return
            pose, self._pose = self._pose, None
        if pose is not None:
            with contextlib.suppress(RoverLinkError):
                robot.odometry.reset(pose.x_m, pose.y_m, pose.theta_rad)
        self._watch(robot)
        with self._lock:
            self._robot = robot
            self._port_error = ""
        log.warning(
            "%s: connected again (%s, boot_id 0x%08X)", robot.url, robot.identity.robot_name, robot.identity.boot_id
        )

    # == closing =====================================================================================
    def close(self) -> None:
        """Stop reconnecting and the supervisor's thread, then close the robot (it disarms)."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            worker = self._worker
        self._jobs.put(None)
        if worker is not None:
            worker.join(timeout=5.0)
        robot = self._connection.stop() if self._connection is not None else None
        for one in {id(r): r for r in (robot, self.robot) if r is not None}.values():
            with contextlib.suppress(RoverLinkError):
                one.close()

    def __enter__(self) -> Supervisor:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<Supervisor {self.robot.url} link {self._link(self.robot)}>"


def _why_unusable(robot: Robot) -> str:
    """What a broken robot's calls raise (the port's error), as text."""
    try:
        robot.wait_feedback(0.001)
    except RoverLinkError as exc:
        return str(exc)
    return f"{robot.url}: the robot is {robot.state}"
