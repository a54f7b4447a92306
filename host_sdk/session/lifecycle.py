"""The link's life: its state (LinkState) and the transitions that change every part of the session
at once: a session opens, a reset ends it, the firmware is incompatible, the robot is closed or its
link breaks.

Reset detection (receive.py): a new boot_id in FEEDBACK or a boot IDENTITY, a NACK(NO_SESSION) or
an ARM refused for BOOT_ID_MISMATCH ends the session: disarmed, setpoint dropped, pending requests
failed with SessionResetError, and the handshake starts again by itself.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from host_sdk.errors import IncompatibleFirmwareError, RoverLinkError, SessionResetError
from host_sdk.session.arming import Arming
from host_sdk.session.counters import HostCounters
from host_sdk.session.events import Event, Failed, Opened, Ready, ResetDetected
from host_sdk.session.feedback import FeedbackTracker
from host_sdk.session.handshake import Handshake
from host_sdk.session.options import LinkState, SessionOptions
from host_sdk.session.pings import TimeSync
from host_sdk.session.reliable import RequestQueue
from host_sdk.session.setpoints import SetpointKeeper
from host_sdk.session.wire import Wire
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH
from protocol.generated.messages import Arm, GetConfig, Identity


@dataclass(frozen=True, slots=True)
class Parts:
    """The session's parts, as the Session makes them for Lifecycle and Receiver."""

    options: SessionOptions
    counters: HostCounters
    wire: Wire
    handshake: Handshake
    sync: TimeSync
    setpoints: SetpointKeeper
    arming: Arming
    requests: RequestQueue
    feedback: FeedbackTracker
    emit: Callable[[Event], None]


class Lifecycle:
    """The link's state, why it ended, and the reset still to report to the user."""

    def __init__(self, parts: Parts) -> None:
        self._p = parts
        self._state = LinkState.CONNECTING
        self._error: RoverLinkError | None = None
        """Why the session cannot go on (incompatible firmware, a broken link)."""
        self._reset_pending: tuple[int, int | None, str] | None = None
        self._rearm_after_open = False

    @property
    def state(self) -> LinkState:
        return self._state

    @property
    def error(self) -> RoverLinkError | None:
        return self._error

    def start(self, now: float) -> None:
        self._state = LinkState.CONNECTING
        self._p.handshake.start(now)

    def hello(self, now: float) -> None:
        # The GET_CONFIG behind the HELLO is a reliable request the firmware remembers.
        self._p.requests.note_sent(GetConfig.MSG_ID, self._p.handshake.send_hello(now))

    def open(self, msg: Identity, now: float) -> None:
        """Our HELLO was answered by `msg`: the session is open (disarmed, config to be read)."""
        p = self._p
        reconnect = p.handshake.open(msg, now)
        self._state = LinkState.OPEN
        p.arming.clear()
        p.sync.start(now)
        p.feedback.new_boot()
        identity = p.handshake.identity
        assert identity is not None
        p.emit(Opened(identity, reconnect))
        if self._rearm_after_open:
            self._rearm_after_open = False
            p.requests.push_front(Arm(boot_id=msg.boot_id))
        p.requests.pump(now)

    def check_ready(self, now: float) -> None:
        if self._state is LinkState.OPEN and self._p.handshake.announce_ready(now):
            self._p.emit(Ready())

    def lost(self, now: float, new_boot_id: int | None, why: str) -> None:
        """The board's session with us is gone (reset, brown-out, or closed): disarmed, setpoint
        dropped, pending requests failed with SessionResetError, and the handshake starts again."""
        if self._state is not LinkState.OPEN:
            return
        p = self._p
        old = p.handshake.boot_id or 0
        p.counters.resets_detected += 1
        was_armed = p.arming.armed or p.arming.failsafe is not None or p.setpoints.live
        p.arming.clear()
        p.setpoints.drop()
        self._fail_pending(SessionResetError(old, new_boot_id, why), inflight_first=True)
        p.sync.reset()
        gap = p.feedback.counts_lost(now)  # keep the pose, re-anchor the counts, widen its uncertainty
        p.wire.renumbered()
        p.handshake.restart(now)
        p.requests.forget_sent()
        self._state = LinkState.CONNECTING
        if p.options.auto_rearm and was_armed:
            self._rearm_after_open = True
        else:
            self._reset_pending = (old, new_boot_id, why)
        p.emit(ResetDetected(old, new_boot_id, why))
        if gap is not None:
            p.emit(gap)
        self.hello(now)

    def incompatible(self, msg: Identity) -> None:
        """The firmware speaks another protocol version or spec: fail closed."""
        p = self._p
        self._state = LinkState.INCOMPATIBLE
        p.arming.disarm()
        p.setpoints.drop()
        self._error = error = IncompatibleFirmwareError(
            p.options.url, msg.protocol_version, msg.spec_hash, PROTOCOL_VERSION, SPEC_HASH, robot_name=msg.robot_name
        )
        self._fail_pending(error)
        p.emit(Failed(error))

    def close(self) -> None:
        self._end(LinkState.CLOSED, None)

    def fail(self, error: RoverLinkError) -> None:
        """The link under the session failed: everything pending fails with `error`."""
        if self._state in (LinkState.CLOSED, LinkState.BROKEN):
            return
        self._error = error
        self._end(LinkState.BROKEN, error)
        self._p.emit(Failed(error))

    @property
    def reset_pending(self) -> bool:
        return self._reset_pending is not None

    def take_reset(self) -> SessionResetError | None:
        """The SessionResetError to raise on the user's next command (once), if a reset happened."""
        pending, self._reset_pending = self._reset_pending, None
        if pending is None:
            return None
        old, new, why = pending
        boot_id = self._p.handshake.boot_id
        if new is None and boot_id is not None and boot_id != old:
            new = boot_id
        return SessionResetError(old, new, why)

    def _end(self, state: LinkState, error: RoverLinkError | None) -> None:
        p = self._p
        self._state = state
        p.arming.clear()
        p.setpoints.drop()
        for req in p.requests.drain(inflight_first=False):
            why = error or RoverLinkError(f"{req.name}: the robot was closed before it was answered")
            p.requests.finish(req, None, why)

    def _fail_pending(self, error: RoverLinkError, inflight_first: bool = False) -> None:
        for req in self._p.requests.drain(inflight_first):
            self._p.requests.finish(req, None, error)
