"""The host's session with a RoverLink board, as a sans-I/O state machine.

It never touches a port, a clock or a thread. The runner feeds it bytes (`receive`) and the time
(`poll`), and takes back the bytes to send (`outgoing`) and what happened (`take_events`):

    session = Session(SessionOptions(...))
    session.start(now)
    while True:
        transport.write(session.outgoing())
        data = transport.read(timeout=session.next_deadline() - now)
        now = clock()
        session.receive(data, now)
        session.poll(now)
        for event in session.take_events(): ...

Because time is an argument, the same code runs against a serial port on the wall clock and
against the emulator on its virtual clock, and every timer is testable.

What it does (docs/sdk.md has the full semantics):

- Handshake: HELLO (with a GET_CONFIG right behind it, so one round trip gives both the
  session and the configuration) every `hello_interval_s` until an IDENTITY answers one of them;
  a boot announcement is answered at once, so ready follows boot by one round trip. A protocol
  version or spec hash that differs fails closed (`IncompatibleFirmwareError`).
- Reset detection: a new boot_id in FEEDBACK or a boot IDENTITY, a NACK(NO_SESSION) or an ARM
  refused for BOOT_ID_MISMATCH ends the session: disarmed, setpoint dropped, pending requests
  failed with SessionResetError, and the handshake starts again by itself.
- Reliable requests: one in flight at a time (the firmware remembers only the last one for its
  duplicate check), retried with the same seq, failed after `tries`. A new request never reuses
  the (msg_id, seq) of the previous one (a PING takes the seq instead), so the firmware can never
  mistake it for a duplicate.
- Setpoints: latest wins; the current one is repeated every `keepalive_s` while it is live
  (`hold_s` after the user gave it). When it expires the session sends nothing that would feed
  the watchdog while armed, so the firmware fails safe when the user's program stops commanding.
- Time sync: PING/PONG into a least-squares ClockSync; FEEDBACK times are mapped to host time.
"""

from __future__ import annotations

import enum
from collections import deque
from dataclasses import dataclass, field

from host_sdk.errors import (
    IncompatibleFirmwareError,
    NackError,
    RequestTimeoutError,
    RoverLinkError,
    SessionResetError,
)
from host_sdk.framing import Frame, FrameDecoder, encode_frame
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.odometry import Odometry, Pose
from host_sdk.session.types import FeedbackSample, LinkStatistics, RobotIdentity, RttStats
from host_sdk.timesync import ClockSync, Unwrapper
from protocol.codec.message import Delivery, Message
from protocol.generated.constants import FEEDBACK_HZ_DEFAULT, PROTOCOL_VERSION, SPEC_HASH, WATCHDOG_DEFAULT_MS
from protocol.generated.enums import FailsafeReason, FeedbackMode, IdentityReason, LogLevel, NackReason, Status
from protocol.generated.messages import (
    BY_ID,
    Ack,
    Arm,
    Config,
    Disarm,
    Feedback,
    GetConfig,
    Hello,
    Identity,
    LinkStats,
    Log,
    Nack,
    Pid,
    Ping,
    Pong,
    SaveConfig,
    SetAckermann,
    SetConfig,
    SetWheelSpeeds,
)
from protocol.generated.structs import DECODER_COUNTERS

_I32 = 1 << 32
_EPS = 1e-6  # timers fire this early rather than a poll late (float time)
CONFIG_FIELDS = tuple(f.name for f in SetConfig.FIELDS)


class LinkState(enum.Enum):
    """Where the host's side of the session is."""

    CONNECTING = "connecting"
    """Sending HELLO until an IDENTITY answers (first connect, or after a reset)."""
    OPEN = "open"
    """The board accepted our HELLO: requests and (once armed) setpoints flow."""
    INCOMPATIBLE = "incompatible"
    """The firmware speaks another protocol version or spec: nothing more is sent."""
    CLOSED = "closed"


@dataclass(frozen=True, slots=True)
class SessionOptions:
    """Timing and mode of a session. Seconds everywhere."""

    watchdog_s: float = WATCHDOG_DEFAULT_MS / 1000
    feedback_mode: FeedbackMode = FeedbackMode.STREAM
    feedback_hz: int = FEEDBACK_HZ_DEFAULT
    """Requested stream rate; 0 asks for the board's configured default."""
    hello_interval_s: float = 0.1
    request_timeout_s: float = 0.25
    """Per try; SAVE_CONFIG gets `save_timeout_s` (EEPROM writes stall the board's loop)."""
    save_timeout_s: float = 1.5
    request_tries: int = 5
    command_timeout_s: float | None = None
    """How long a setpoint stays live without being renewed; None: watchdog_s / 2."""
    keepalive_s: float | None = None
    """How often a live setpoint is repeated; None: watchdog_s / 4."""
    ping_interval_s: float = 1.0
    auto_rearm: bool = False
    url: str = ""
    baud: int = 0

    @property
    def command_timeout(self) -> float:
        return self.command_timeout_s if self.command_timeout_s is not None else self.watchdog_s / 2

    @property
    def keepalive(self) -> float:
        return self.keepalive_s if self.keepalive_s is not None else self.watchdog_s / 4


# -- events ---------------------------------------------------------------------------------------
@dataclass(frozen=True, slots=True)
class Opened:
    identity: RobotIdentity
    reconnect: bool
    """True when this session replaces one that a reset ended."""


@dataclass(frozen=True, slots=True)
class Ready:
    """Identity and configuration are known: the robot can be used."""


@dataclass(frozen=True, slots=True)
class ResetDetected:
    old_boot_id: int
    new_boot_id: int | None
    why: str


@dataclass(frozen=True, slots=True)
class FeedbackReceived:
    sample: FeedbackSample


@dataclass(frozen=True, slots=True)
class LogReceived:
    level: LogLevel
    text: str


@dataclass(frozen=True, slots=True)
class FailsafeEntered:
    reason: FailsafeReason
    predicted: bool
    """True when the host inferred it (it stopped sending for a watchdog period) before the board said so."""


@dataclass(frozen=True, slots=True)
class Failed:
    error: RoverLinkError


@dataclass(frozen=True, slots=True)
class RequestFinished:
    request: Request


Event = Opened | Ready | ResetDetected | FeedbackReceived | LogReceived | FailsafeEntered | Failed | RequestFinished


# -- reliable requests ----------------------------------------------------------------------------
_REPLY_TYPES: dict[str, type[Message]] = {"GET_CONFIG": Config, "GET_PID": Pid, "GET_LINK_STATS": LinkStats}


class Request:
    """A reliable request and, once `done`, its `reply` (ACK or data) or its `error`."""

    __slots__ = (
        "boot_id",
        "deadline",
        "done",
        "error",
        "internal",
        "msg",
        "reply",
        "sent",
        "seq",
        "timeout_s",
        "tries",
    )

    def __init__(self, msg: Message, tries: int, timeout_s: float, boot_id: int | None, internal: bool) -> None:
        self.msg = msg
        self.tries = tries
        self.timeout_s = timeout_s
        self.boot_id = boot_id
        self.internal = internal
        self.seq: int | None = None
        self.sent = 0
        self.deadline = 0.0
        self.done = False
        self.reply: Message | None = None
        self.error: RoverLinkError | None = None

    @property
    def name(self) -> str:
        return self.msg.NAME

    def __repr__(self) -> str:
        state = "done" if self.done else f"sent {self.sent}x"
        return f"<Request {self.msg.NAME} seq={self.seq} {state}>"


@dataclass(slots=True)
class _Counters:
    frames_sent: int = 0
    bytes_sent: int = 0
    seq_gaps: int = 0
    feedback_received: int = 0
    setpoints_sent: int = 0
    keepalives_sent: int = 0
    hellos_sent: int = 0
    requests_sent: int = 0
    retries: int = 0
    request_timeouts: int = 0
    pings_sent: int = 0
    pongs_received: int = 0
    resets_detected: int = 0
    reconnects: int = 0
    nacks: dict[str, int] = field(default_factory=dict)
    rtts: deque[float] = field(default_factory=lambda: deque(maxlen=64))
    rtt_count: int = 0


class Session:
    """The host side of one link (it outlives board resets: each reset opens a new firmware session)."""

    def __init__(self, options: SessionOptions, kinematics: DiffDrive | Ackermann | None = None) -> None:
        self.options = options
        self.state = LinkState.CONNECTING
        self.identity: RobotIdentity | None = None
        self.config: SetConfig | None = None
        self.armed = False
        self.failsafe: FailsafeReason | None = None
        """Latched FAILSAFE the board reported (or the host predicted); None when not in failsafe."""
        self.failsafe_predicted = False
        self.error: RoverLinkError | None = None
        """Why the session cannot go on (incompatible firmware)."""
        self.setpoint_error: NackError | None = None
        """A setpoint the board refused (out of range, unsupported): raised on the user's next command."""
        self.latest: FeedbackSample | None = None
        self.clock = ClockSync()
        self.kinematics = kinematics
        self.odometry: Odometry | None = Odometry(kinematics) if kinematics is not None else None
        self.decoder = FrameDecoder()
        self.started_s: float | None = None
        self.ready_s: float | None = None
        self.opened_s: float | None = None
        self.last_rx_s: float | None = None
        self.last_feedback_s: float | None = None
        self.identities_seen = 0
        self._n = _Counters()
        self._out: list[bytes] = []
        self._events: list[Event] = []
        self._tx_seq = 0
        self._rx_seq: int | None = None
        self._next_hello = 0.0
        self._hello_seqs: dict[int, int] = {}  # HELLO seq -> the GET_CONFIG seq sent right behind it
        self._handshake_config_seqs: set[int] = set()
        self._opened_once = False
        self._queue: deque[Request] = deque()
        self._inflight: Request | None = None
        self._last_reliable_key: tuple[int, int] | None = None
        self._setpoint: Message | None = None
        self._setpoint_seq = -1
        self._setpoint_expires = 0.0
        self._setpoint_sent = 0.0
        self._last_tx = 0.0
        self._pings: dict[int, float] = {}
        self._next_ping = 0.0
        self._reset_pending: tuple[int, int | None, str] | None = None
        self._rearm_after_open = False
        self._counts_raw: tuple[int, ...] | None = None
        self._counts: list[int] = []
        self._tick = Unwrapper(16)
        self._prev_steering = 0.0
        self._feedback_index = 0
        self._config_fresh = False
        self._ready_announced = False

    # == inputs ===================================================================================
    def start(self, now: float) -> None:
        """Begin the handshake: the first HELLO goes out now."""
        self.started_s = now
        self.state = LinkState.CONNECTING
        self._next_hello = now
        self.poll(now)

    def receive(self, data: bytes, now: float) -> None:
        """Bytes from the board."""
        if not data or self.state is LinkState.CLOSED:
            return
        for event in self.decoder.feed(data):
            if isinstance(event, Frame):
                self.last_rx_s = now
                self._on_frame(event.message, event.seq, now)

    def poll(self, now: float) -> None:
        """Run the timers: HELLO repeats, request retries, keep-alives, PINGs."""
        if self.state is LinkState.CONNECTING:
            if now >= self._next_hello - _EPS:
                self._send_hello(now)
            self._expire_inflight(now)
            return
        if self.state is not LinkState.OPEN:
            return
        self._expire_inflight(now)
        self._refresh_config(now)
        self._pump_queue(now)
        self._keepalive(now)
        self._predict_failsafe(now)
        if now >= self._next_ping - _EPS:
            if self._quiet(now):
                self._next_ping = now + self.options.ping_interval_s / 4
            else:
                self._send_ping(now)

    def next_deadline(self, now: float) -> float:
        """The latest time `poll` must run again (a runner may call it earlier)."""
        times = [now + 0.05]
        if self.state is LinkState.CONNECTING:
            times.append(self._next_hello)
        if self._inflight is not None:
            times.append(self._inflight.deadline)
        if self.state is LinkState.OPEN:
            times.append(self._next_ping)
            if self._setpoint is not None:
                times.append(min(self._setpoint_sent + self.options.keepalive, self._setpoint_expires))
            if self.armed:
                times.append(self._last_tx + self.watchdog_s + 0.02)
        return min(times)

    # == user operations ===========================================================================
    def submit(self, msg: Message, now: float, *, tries: int | None = None, timeout_s: float | None = None) -> Request:
        """Queue a reliable request; it is sent when the session is open and none is in flight."""
        if timeout_s is None:
            timeout_s = self.options.save_timeout_s if isinstance(msg, SaveConfig) else self.options.request_timeout_s
        req = Request(msg, tries or self.options.request_tries, timeout_s, self.boot_id, internal=False)
        self._queue.append(req)
        if self.state is LinkState.OPEN:
            self._pump_queue(now)
        return req

    def cancel(self, req: Request) -> None:
        """Give up on a request (its answer, if it comes, is ignored)."""
        if req in self._queue:
            self._queue.remove(req)
        if self._inflight is req:
            self._inflight = None
        if not req.done:
            req.done = True
            req.error = RequestTimeoutError(req.name, max(req.sent, 1), req.timeout_s)

    def command(self, msg: SetWheelSpeeds | SetAckermann, now: float, hold_s: float | None = None) -> int:
        """Send a setpoint now and keep it live for `hold_s` (default: command_timeout). Returns its seq."""
        self._setpoint = msg
        self._setpoint_expires = now + (hold_s if hold_s is not None else self.options.command_timeout)
        return self._send_setpoint(now, keepalive=False)

    def release(self) -> None:
        """Stop repeating the current setpoint (the board keeps it until the watchdog)."""
        self._setpoint = None

    @property
    def setpoint_live(self) -> bool:
        return self._setpoint is not None

    @property
    def last_setpoint_seq(self) -> int:
        return self._setpoint_seq

    def take_reset(self) -> SessionResetError | None:
        """The SessionResetError to raise on the user's next command (once), if a reset happened."""
        pending, self._reset_pending = self._reset_pending, None
        if pending is None:
            return None
        old, new, why = pending
        if new is None and self.identity is not None and self.identity.boot_id != old:
            new = self.identity.boot_id
        return SessionResetError(old, new, why)

    def close(self) -> None:
        self.state = LinkState.CLOSED
        self._setpoint = None
        for req in [*self._queue, *([self._inflight] if self._inflight else [])]:
            if not req.done:
                req.done = True
                req.error = RoverLinkError(f"{req.name}: the robot was closed before it was answered")
        self._queue.clear()
        self._inflight = None

    # == outputs ===================================================================================
    def outgoing(self) -> bytes:
        """Bytes to write to the board, in order (taking them empties the buffer)."""
        if not self._out:
            return b""
        data = b"".join(self._out)
        self._out.clear()
        return data

    def take_events(self) -> list[Event]:
        events, self._events = self._events, []
        return events

    # == state =====================================================================================
    @property
    def ready(self) -> bool:
        return self.state is LinkState.OPEN and self._config_fresh

    @property
    def boot_id(self) -> int | None:
        return self.identity.boot_id if self.identity is not None else None

    @property
    def watchdog_s(self) -> float:
        if self.identity is not None and self.identity.watchdog_ms:
            return self.identity.watchdog_ms / 1000
        return self.options.watchdog_s

    @property
    def feedback_mode(self) -> FeedbackMode:
        return self.identity.feedback_mode if self.identity is not None else self.options.feedback_mode

    def set_kinematics(self, kinematics: DiffDrive | Ackermann | None) -> None:
        self.kinematics = kinematics
        self.odometry = Odometry(kinematics) if kinematics is not None else None

    def stats(self, now: float) -> LinkStatistics:
        n, d = self._n, self.decoder.stats
        rtt = None
        if n.rtts:
            rtts = list(n.rtts)
            rtt = RttStats(rtts[-1], min(rtts), sum(rtts) / len(rtts), max(rtts), n.rtt_count)
        synced = self.clock.synced
        return LinkStatistics(
            **{name: getattr(d, name) for name in DECODER_COUNTERS},
            frames_sent=n.frames_sent,
            bytes_sent=n.bytes_sent,
            bytes_received=d.bytes_received,
            seq_gaps=n.seq_gaps,
            feedback_received=n.feedback_received,
            setpoints_sent=n.setpoints_sent,
            keepalives_sent=n.keepalives_sent,
            hellos_sent=n.hellos_sent,
            requests_sent=n.requests_sent,
            retries=n.retries,
            request_timeouts=n.request_timeouts,
            nacks=dict(n.nacks),
            pings_sent=n.pings_sent,
            pongs_received=n.pongs_received,
            rtt=rtt,
            clock_offset_us=self.clock.offset_us(now) if synced else None,
            clock_drift_ppm=self.clock.drift_ppm if self.clock.samples >= 2 else None,
            resets_detected=n.resets_detected,
            reconnects=n.reconnects,
            connect_time_s=(self.ready_s - self.started_s)
            if self.ready_s is not None and self.started_s is not None
            else None,
        )

    # == sending ===================================================================================
    def _send(self, msg: Message, now: float, seq: int | None = None) -> int:
        if seq is None:
            seq = self._tx_seq
            self._tx_seq = (self._tx_seq + 1) & 0xFF
        wire = encode_frame(msg, seq)
        self._out.append(wire)
        self._n.frames_sent += 1
        self._n.bytes_sent += len(wire)
        self._last_tx = now
        return seq

    def _send_hello(self, now: float) -> None:
        o = self.options
        hello = Hello(
            protocol_version=PROTOCOL_VERSION,
            spec_hash=SPEC_HASH,
            watchdog_ms=max(0, min(Hello.WATCHDOG_MS_MAX, round(o.watchdog_s * 1000))),
            feedback_mode=o.feedback_mode,
            feedback_hz=max(0, min(255, o.feedback_hz)),
        )
        hello_seq = self._send(hello, now)
        config_seq = self._send(GetConfig(), now)
        self._last_reliable_key = (GetConfig.MSG_ID, config_seq)
        self._hello_seqs[hello_seq] = config_seq
        self._handshake_config_seqs.add(config_seq)
        if len(self._hello_seqs) > 32:
            oldest = next(iter(self._hello_seqs))
            self._handshake_config_seqs.discard(self._hello_seqs.pop(oldest))
        self._n.hellos_sent += 1
        self._next_hello = now + o.hello_interval_s

    def _send_ping(self, now: float) -> None:
        stamp = round(now * 1e6) & 0xFFFFFFFF
        self._pings[stamp] = now
        if len(self._pings) > 16:
            del self._pings[next(iter(self._pings))]
        self._send(Ping(host_time_us=stamp), now)
        self._n.pings_sent += 1
        early = self.clock.samples < 8
        self._next_ping = now + (min(0.2, self.options.ping_interval_s) if early else self.options.ping_interval_s)

    def _send_setpoint(self, now: float, keepalive: bool) -> int:
        assert self._setpoint is not None
        seq = self._send(self._setpoint, now)
        self._setpoint_seq = seq
        self._setpoint_sent = now
        self._n.setpoints_sent += 1
        if keepalive:
            self._n.keepalives_sent += 1
        return seq

    def _keepalive(self, now: float) -> None:
        if self._setpoint is None:
            return
        if now >= self._setpoint_expires - _EPS:
            self._setpoint = None  # the user stopped commanding: go quiet, let the watchdog act
            return
        if self.armed and now - self._setpoint_sent >= self.options.keepalive - _EPS:
            self._send_setpoint(now, keepalive=True)

    def _quiet(self, now: float) -> bool:
        """Armed with no live command: send nothing that would feed the board's watchdog."""
        return self.armed and self._setpoint is None

    def _predict_failsafe(self, now: float) -> None:
        # Nothing sent for a watchdog period (plus two ticks) while armed: the board has failed
        # safe by now, whether or not its FEEDBACK saying so gets through (lockstep sends none).
        if self.armed and now - self._last_tx > self.watchdog_s + 0.02:
            self.armed = False
            self.failsafe = FailsafeReason.COMM_TIMEOUT
            self.failsafe_predicted = True
            self._events.append(FailsafeEntered(FailsafeReason.COMM_TIMEOUT, predicted=True))

    # -- reliable requests ---------------------------------------------------------------------------
    def _pump_queue(self, now: float) -> None:
        while self._inflight is None and self._queue and self.state is LinkState.OPEN:
            req = self._queue.popleft()
            if req.done:
                continue
            if req.boot_id is not None and req.boot_id != self.boot_id and not req.internal:
                # Queued for a session that a reset ended: never apply it to the new one.
                self._finish(req, None, SessionResetError(req.boot_id, self.boot_id, "before it was sent"))
                continue
            if (req.msg.MSG_ID, self._tx_seq) == self._last_reliable_key:
                # The firmware would take this as a duplicate of the last request: burn the seq.
                self._send_ping(now)
            req.seq = self._send(req.msg, now)
            self._last_reliable_key = (req.msg.MSG_ID, req.seq)
            req.sent = 1
            req.deadline = now + req.timeout_s
            self._inflight = req
            self._n.requests_sent += 1

    def _expire_inflight(self, now: float) -> None:
        req = self._inflight
        if req is None or now < req.deadline - _EPS:
            return
        if req.sent >= req.tries or self.state is not LinkState.OPEN:
            self._n.request_timeouts += 1
            self._inflight = None
            self._finish(req, None, RequestTimeoutError(req.name, req.sent, req.timeout_s))
            self._pump_queue(now)
            return
        assert req.seq is not None
        self._send(req.msg, now, seq=req.seq)  # a retry carries the same seq: applied once
        req.sent += 1
        req.deadline = now + req.timeout_s
        self._n.retries += 1

    def _finish(self, req: Request, reply: Message | None, error: RoverLinkError | None) -> None:
        req.done = True
        req.reply = reply
        req.error = error
        if error is None and reply is not None:
            self._apply_reply(req, reply)
        self._events.append(RequestFinished(req))

    def _apply_reply(self, req: Request, reply: Message) -> None:
        msg = req.msg
        if isinstance(reply, Config):
            self.config = _config_of(reply)
            self._config_fresh = True
        elif isinstance(msg, SetConfig):
            self.config = msg
        elif isinstance(msg, Arm):
            self.armed = True
            self.failsafe = None
            self.failsafe_predicted = False
        elif isinstance(msg, Disarm):
            self.armed = False
            self.failsafe = None
            self.failsafe_predicted = False
            self._setpoint = None

    def _match(self, reply: Message) -> Request | None:
        req = self._inflight
        if req is None or req.seq is None:
            return None
        if isinstance(reply, (Ack, Nack)):
            return req if reply.req_id == req.msg.MSG_ID and reply.req_seq == req.seq else None
        expected = _REPLY_TYPES.get(req.msg.NAME)
        if expected is not None and isinstance(reply, expected) and getattr(reply, "req_seq", -1) == req.seq:
            return req
        return None

    # == receiving =================================================================================
    def _on_frame(self, msg: Message, seq: int, now: float) -> None:
        if isinstance(msg, Identity):
            self._on_identity(msg, now)
        elif isinstance(msg, Feedback):
            self._on_feedback(msg, now)
        self._account_seq(seq)
        if isinstance(msg, (Identity, Feedback)):
            return
        if isinstance(msg, Pong):
            self._on_pong(msg, now)
        elif isinstance(msg, Log):
            self._events.append(LogReceived(msg.level, msg.text))
        elif isinstance(msg, Nack):
            self._on_nack(msg, now)
        elif msg.DELIVERY is Delivery.RELIABLE:
            self._on_reply(msg, now)

    def _account_seq(self, seq: int) -> None:
        last = self._rx_seq
        if last is not None:
            self._n.seq_gaps += (seq - last - 1) % 256
        self._rx_seq = seq

    def _on_reply(self, msg: Message, now: float) -> None:
        if isinstance(msg, Config) and msg.req_seq in self._handshake_config_seqs:
            if self.state is LinkState.OPEN:
                self._handshake_config_seqs.discard(msg.req_seq)
                self.config = _config_of(msg)
                self._config_fresh = True
                self._check_ready(now)
            return
        req = self._match(msg)
        if req is None:
            return  # the answer to a retry we no longer wait for
        self._inflight = None
        self._finish(req, msg, None)
        self._check_ready(now)
        self._pump_queue(now)

    def _on_nack(self, msg: Nack, now: float) -> None:
        counts = self._n.nacks
        counts[msg.reason.name] = counts.get(msg.reason.name, 0) + 1
        if msg.req_id == GetConfig.MSG_ID and msg.req_seq in self._handshake_config_seqs:
            return  # the GET_CONFIG behind a HELLO that did not open the session
        req = self._match(msg)
        if msg.req_id in (SetWheelSpeeds.MSG_ID, SetAckermann.MSG_ID):
            self._on_setpoint_nack(msg, now)
            return
        if req is not None:
            self._inflight = None
            if msg.reason is NackReason.BOOT_ID_MISMATCH and isinstance(req.msg, Arm):
                self._finish(req, None, SessionResetError(req.msg.boot_id, None, "ARM named a boot that is gone"))
                self._session_lost(now, None, "the board refused ARM for another boot_id")
                return
            if msg.reason is NackReason.NO_SESSION:
                old = self.boot_id or 0
                self._finish(req, None, SessionResetError(old, None, "the board has no session"))
                self._session_lost(now, None, f"{req.name} answered NO_SESSION")
                return
            self._finish(req, None, _nack_error(req.msg, msg))
            self._pump_queue(now)
        elif msg.reason is NackReason.NO_SESSION and self.state is LinkState.OPEN:
            self._session_lost(now, None, "the board answered NO_SESSION")

    def _on_setpoint_nack(self, msg: Nack, now: float) -> None:
        if self.state is not LinkState.OPEN:
            return
        reason = msg.reason
        if reason is NackReason.NO_SESSION:
            self._session_lost(now, None, "a setpoint was answered NO_SESSION")
        elif reason is NackReason.FAILSAFE:
            if self.armed or self.failsafe is None:
                try:
                    why = FailsafeReason(msg.detail)
                except ValueError:
                    why = FailsafeReason.NONE
                self._enter_failsafe(why, predicted=False)
        elif reason is NackReason.NOT_ARMED:
            self.armed = False
            self._setpoint = None
        else:
            request = SetWheelSpeeds if msg.req_id == SetWheelSpeeds.MSG_ID else SetAckermann
            self.setpoint_error = _nack_error(request(0, 0), msg)
            self._setpoint = None

    def _enter_failsafe(self, reason: FailsafeReason, predicted: bool) -> None:
        fresh = self.failsafe is None or self.failsafe_predicted
        self.armed = False
        self.failsafe = reason
        self.failsafe_predicted = predicted
        self._setpoint = None
        if fresh:
            self._events.append(FailsafeEntered(reason, predicted))

    def _on_pong(self, msg: Pong, now: float) -> None:
        sent = self._pings.pop(msg.host_time_us, None)
        if sent is None:
            return
        self._n.pongs_received += 1
        if self.state is not LinkState.OPEN:
            return
        self._n.rtts.append(now - sent)
        self._n.rtt_count += 1
        self.clock.add(sent, now, msg.mcu_time_us)

    def _on_identity(self, msg: Identity, now: float) -> None:
        self.identities_seen += 1
        if msg.protocol_version != PROTOCOL_VERSION or msg.spec_hash != SPEC_HASH:
            if self.state is not LinkState.CLOSED:
                self._incompatible(msg)
            return
        if msg.reason is IdentityReason.BOOT:
            if self.state is LinkState.OPEN and msg.boot_id != self.boot_id:
                self._session_lost(now, msg.boot_id, "the board announced a new boot")  # sends HELLO
            elif self.state is LinkState.CONNECTING:
                self._send_hello(now)  # answer the announcement at once: ready one round trip after boot
            return
        if msg.reason is IdentityReason.HELLO_REJECTED:
            if msg.hello_seq in self._hello_seqs:
                self._incompatible(msg)
            return
        ours = self._hello_seqs.pop(msg.hello_seq, None) is not None
        if self.state is LinkState.CONNECTING:
            if not ours:
                return  # an answer to someone else's HELLO
            self._open(msg, now)
        elif self.state is LinkState.OPEN:
            if msg.boot_id != self.boot_id:
                self._session_lost(now, msg.boot_id, "an IDENTITY names a new boot")
                return
            # The board re-opened the session (a HELLO of ours that crossed the first answer):
            # it is disarmed and its duplicate memory is cleared.
            self.identity = RobotIdentity.of(msg, now)
            if self.armed:
                self.armed = False
                self._setpoint = None

    def _open(self, msg: Identity, now: float) -> None:
        reconnect = self._opened_once
        self.identity = RobotIdentity.of(msg, now)
        self.state = LinkState.OPEN
        self.opened_s = now
        self.armed = False
        self.failsafe = None
        self.failsafe_predicted = False
        self._config_fresh = False
        self._ready_announced = False
        self._next_ping = now + 0.02
        self._counts_raw = None
        self._tick = Unwrapper(16)
        if reconnect:
            self._n.reconnects += 1
        self._opened_once = True
        self._events.append(Opened(self.identity, reconnect))
        if self._rearm_after_open:
            self._rearm_after_open = False
            o = self.options
            self._queue.appendleft(Request(Arm(boot_id=msg.boot_id), o.request_tries, o.request_timeout_s, None, True))
        self._pump_queue(now)

    def _refresh_config(self, now: float) -> None:
        """The GET_CONFIG behind the HELLO normally answers in the same round trip; ask again if not."""
        if self._config_fresh or self.opened_s is None or now < self.opened_s + self.options.request_timeout_s:
            return
        pending = [*self._queue, *([self._inflight] if self._inflight else [])]
        if not any(isinstance(r.msg, GetConfig) for r in pending):
            o = self.options
            self._queue.appendleft(Request(GetConfig(), o.request_tries, o.request_timeout_s, None, True))

    def _check_ready(self, now: float) -> None:
        if self.state is LinkState.OPEN and self._config_fresh and not self._ready_announced:
            self._ready_announced = True
            if self.ready_s is None:
                self.ready_s = now
            self._events.append(Ready())

    def _incompatible(self, msg: Identity) -> None:
        self.state = LinkState.INCOMPATIBLE
        self.armed = False
        self._setpoint = None
        o = self.options
        self.error = IncompatibleFirmwareError(
            o.url, msg.protocol_version, msg.spec_hash, PROTOCOL_VERSION, SPEC_HASH, robot_name=msg.robot_name
        )
        for req in [*self._queue, *([self._inflight] if self._inflight else [])]:
            if not req.done:
                self._finish(req, None, self.error)
        self._queue.clear()
        self._inflight = None
        self._events.append(Failed(self.error))

    def _session_lost(self, now: float, new_boot_id: int | None, why: str) -> None:
        """The board's session with us is gone (reset, brown-out, or closed): start again."""
        if self.state is not LinkState.OPEN:
            return
        old = self.boot_id or 0
        self._n.resets_detected += 1
        was_armed = self.armed or self.failsafe is not None or self._setpoint is not None
        self.armed = False
        self.failsafe = None
        self.failsafe_predicted = False
        self._setpoint = None
        error = SessionResetError(old, new_boot_id, why)
        pending = [*([self._inflight] if self._inflight else []), *self._queue]
        self._inflight = None
        self._queue.clear()
        for req in pending:
            if not req.done:
                self._finish(req, None, error)
        self.clock.reset()
        self._pings.clear()
        if self.odometry is not None:
            pose = self.odometry.pose
            self.odometry.reset(pose.x_m, pose.y_m, pose.theta_rad)  # keep the pose, re-anchor the counts
        self._counts_raw = None
        self._rx_seq = None
        self._hello_seqs.clear()
        self._handshake_config_seqs.clear()
        self._last_reliable_key = None
        self.state = LinkState.CONNECTING
        self._next_hello = now
        if self.options.auto_rearm and was_armed:
            self._rearm_after_open = True
        else:
            self._reset_pending = (old, new_boot_id, why)
        self._events.append(ResetDetected(old, new_boot_id, why))
        self._send_hello(now)

    def _on_feedback(self, msg: Feedback, now: float) -> None:
        if self.state is not LinkState.OPEN:
            return
        if msg.boot_id != self.boot_id:
            self._rx_seq = None  # a new boot numbers its frames from 0 again
            self._session_lost(now, msg.boot_id, "FEEDBACK carries a new boot_id")
            return
        if not msg.status & Status.SESSION:
            self._session_lost(now, msg.boot_id, "the board reports no session")
            return
        self._n.feedback_received += 1
        self.last_feedback_s = now
        status = msg.status
        if status & Status.FAILSAFE:
            self._enter_failsafe(msg.failsafe_reason, predicted=False)
        elif status & Status.ARMED:
            if not self.armed and self.failsafe is None:
                self.armed = True  # an ARM whose ACK was lost was applied all the same
        elif self.armed:
            self.armed = False
            self._setpoint = None
        # Counts and time.
        raw = msg.encoder_counts
        if self._counts_raw is None:
            self._counts = list(raw)
        else:
            for w, (new, old) in enumerate(zip(raw, self._counts_raw, strict=True)):
                d = (new - old) % _I32
                self._counts[w] += d - _I32 if d >= 1 << 31 else d
        self._counts_raw = raw
        mcu_us = self.clock.unwrap(msg.mcu_time_us)
        tick = self._tick(msg.tick)
        steering = msg.steering_mrad / 1000
        pose: Pose | None = None
        if self.odometry is not None:
            pose = self.odometry.update(raw, msg.mcu_time_us, self._prev_steering)
        self._prev_steering = steering
        self._feedback_index += 1
        r_m = 1 / 1000
        sample = FeedbackSample(
            index=self._feedback_index,
            boot_id=msg.boot_id,
            received_s=now,
            host_time_s=self.clock.to_host_s(mcu_us) if self.clock.synced else now,
            mcu_time_us=mcu_us,
            tick=tick,
            status=status,
            failsafe_reason=msg.failsafe_reason,
            encoder_counts=tuple(self._counts),
            wheel_speeds_m_s=tuple(s * r_m for s in msg.wheel_speed_mm_s),
            efforts=tuple(e / 1000 for e in msg.effort_permille),
            steering_rad=steering,
            ack_seq=msg.ack_seq,
            pose=pose,
        )
        self.latest = sample
        self._events.append(FeedbackReceived(sample))


def _config_of(msg: Config) -> SetConfig:
    return SetConfig(**{name: getattr(msg, name) for name in CONFIG_FIELDS})


def _nack_error(request: Message, nack: Nack) -> NackError:
    field_name: str | None = None
    cls = BY_ID.get(nack.req_id, type(request))
    if nack.reason in (NackReason.OUT_OF_RANGE, NackReason.INVALID_CONFIG) and nack.detail < len(cls.FIELDS):
        field_name = cls.FIELDS[nack.detail].name
    hints = {
        NackReason.ARMED: "disarm first (robot.disarm())",
        NackReason.EEPROM_ERROR: "the board's EEPROM did not verify; it may be worn out",
        NackReason.UNSUPPORTED: "this firmware build cannot do that",
        NackReason.INVALID_CONFIG: "fields are in range but inconsistent (steering min <= centre <= max, "
        "servo min < max, ESC min < neutral < max)",
    }
    return NackError(request.NAME, nack.reason, nack.detail, field_name, hints.get(nack.reason, ""))
