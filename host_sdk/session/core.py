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

from host_sdk.errors import (
    IncompatibleFirmwareError,
    NackError,
    RoverLinkError,
    SessionResetError,
)
from host_sdk.framing import Frame
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.session.events import (
    Event,
    Failed,
    FailsafeEntered,
    FeedbackReceived,
    LinkState,
    LogReceived,
    Opened,
    Ready,
    ResetDetected,
)
from host_sdk.session.output import EPS
from host_sdk.session.requests import Request, Requests, config_of
from host_sdk.session.types import LinkStatistics, RobotIdentity, RttStats
from protocol.codec.message import Delivery, Message
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH
from protocol.generated.enums import Capability, FailsafeReason, IdentityReason, NackReason, Status
from protocol.generated.messages import (
    BY_ID,
    Arm,
    Config,
    Feedback,
    GetConfig,
    Identity,
    Log,
    Nack,
    Pong,
    SetAckermann,
    SetWheelSpeeds,
)
from protocol.generated.structs import DECODER_COUNTERS

_SESSION, _FAILSAFE, _ARMED = int(Status.SESSION), int(Status.FAILSAFE), int(Status.ARMED)


class Session(Requests):
    """The host side of one link (it outlives board resets: each reset opens a new firmware session)."""

    # == inputs ===================================================================================
    def start(self, now: float) -> None:
        """Begin the handshake: the first HELLO goes out now."""
        self.started_s = now
        self._state = LinkState.CONNECTING
        self._next_hello = now
        self.poll(now)

    def receive(self, data: bytes, now: float) -> None:
        """Bytes from the board."""
        if not data or self._state is LinkState.CLOSED:
            return
        for event in self.decoder.feed(data):
            if isinstance(event, Frame):
                self._last_rx_s = now
                self._on_frame(event.message, event.seq, now)

    def poll(self, now: float) -> None:
        """Run the timers: HELLO repeats, request retries, keep-alives, PINGs."""
        if self._state is LinkState.CONNECTING:
            if now >= self._next_hello - EPS:
                self._send_hello(now)
            self._expire_inflight(now)
            return
        if self._state is not LinkState.OPEN:
            return
        self._expire_inflight(now)
        self._refresh_config(now)
        self._pump_queue(now)
        self._keepalive(now)
        self._predict_failsafe(now)
        if now >= self._next_ping - EPS:
            if self._quiet(now):
                self._next_ping = now + self.options.ping_interval_s / 4
            else:
                self._send_ping(now)

    def next_deadline(self, now: float) -> float:
        """The latest time `poll` must run again (a runner may call it earlier)."""
        t = now + 0.05
        state = self._state
        if state is LinkState.CONNECTING and self._next_hello < t:
            t = self._next_hello
        inflight = self._inflight
        if inflight is not None and inflight.deadline < t:
            t = inflight.deadline
        if state is LinkState.OPEN:
            t = min(t, self._next_ping)
            if self._setpoint is not None:
                t = min(t, self._setpoint_sent + self.options.keepalive, self._setpoint_expires)
            if self._armed:
                t = min(t, self._last_tx + self.watchdog_s + 0.02)
        return t

    # == user operations ===========================================================================
    def command(self, msg: SetWheelSpeeds | SetAckermann, now: float, hold_s: float | None = None) -> int:
        """Send a setpoint now and keep it live for `hold_s` (default: command_timeout). Returns its seq."""
        self._setpoint = msg
        self._setpoint_expires = now + (hold_s if hold_s is not None else self.options.command_timeout)
        return self._send_setpoint(now, keepalive=False)

    def release(self) -> None:
        """Stop repeating the current setpoint (the board keeps it until the watchdog)."""
        self._setpoint = None

    def close(self) -> None:
        """The robot is closed: nothing more is sent; pending requests fail."""
        self._end(LinkState.CLOSED, None)

    def fail(self, error: RoverLinkError) -> None:
        """The link under the session failed (`error` says how): the robot is unusable. Everything
        pending fails with `error`, the robot is no longer armed, nothing more is sent."""
        if self._state in (LinkState.CLOSED, LinkState.BROKEN):
            return
        self._error = error
        self._end(LinkState.BROKEN, error)
        self._events.append(Failed(error))

    def _end(self, state: LinkState, error: RoverLinkError | None) -> None:
        self._state = state
        self._armed = False
        self._failsafe = None
        self._setpoint = None
        for req in [*self._queue, *([self._inflight] if self._inflight else [])]:
            if not req.done:
                why = error or RoverLinkError(f"{req.name}: the robot was closed before it was answered")
                self._finish(req, None, why)
        self._queue.clear()
        self._inflight = None

    def stop(self, now: float) -> int | None:
        """Zero speed (steering centred) while armed; else only stop repeating the last setpoint.
        Returns the stop setpoint's seq, if one was sent."""
        if not (self._armed and self._state is LinkState.OPEN):
            self._setpoint = None
            return None
        caps = self._identity.capabilities if self._identity is not None else Capability(0)
        zero = SetWheelSpeeds(0, 0) if caps & Capability.DIFF_DRIVE else SetAckermann(0, 0)
        return self.command(zero, now)

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

    def set_kinematics(self, kinematics: DiffDrive | Ackermann | None) -> None:
        """The robot's kinematics for odometry (None: no odometry); a pose already integrated is kept."""
        self._feedback.set_kinematics(kinematics)

    def stats(self, now: float) -> LinkStatistics:
        n, d = self._n, self.decoder.stats
        rtt = None
        if n.rtts:
            rtts = list(n.rtts)
            rtt = RttStats(rtts[-1], min(rtts), sum(rtts) / len(rtts), max(rtts), n.rtt_count)
        synced = self.clock.synced
        return LinkStatistics(
            **{name: getattr(d, name) for name in DECODER_COUNTERS},
            **n.counts(),
            bytes_received=d.bytes_received,
            nacks=dict(n.nacks),
            rtt=rtt,
            clock_offset_us=self.clock.offset_us(now) if synced else None,
            clock_drift_ppm=self.clock.drift_ppm if self.clock.samples >= 2 else None,
            connect_time_s=(self.ready_s - self.started_s)
            if self.ready_s is not None and self.started_s is not None
            else None,
        )

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
            if self._state is LinkState.OPEN:
                self._handshake_config_seqs.discard(msg.req_seq)
                self._config = config_of(msg)
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
        elif msg.reason is NackReason.NO_SESSION and self._state is LinkState.OPEN:
            self._session_lost(now, None, "the board answered NO_SESSION")

    def _on_setpoint_nack(self, msg: Nack, now: float) -> None:
        if self._state is not LinkState.OPEN:
            return
        reason = msg.reason
        if reason is NackReason.NO_SESSION:
            self._session_lost(now, None, "a setpoint was answered NO_SESSION")
        elif reason is NackReason.FAILSAFE:
            if self._armed or self._failsafe is None:
                try:
                    why = FailsafeReason(msg.detail)
                except ValueError:
                    why = FailsafeReason.NONE
                self._enter_failsafe(why, predicted=False)
        elif reason is NackReason.NOT_ARMED:
            self._armed = False
            self._setpoint = None
        else:
            request = SetWheelSpeeds if msg.req_id == SetWheelSpeeds.MSG_ID else SetAckermann
            self._setpoint_error = _nack_error(request, msg)  # setpoints are not kept: the value is unknown
            self._setpoint = None

    def _enter_failsafe(self, reason: FailsafeReason, predicted: bool) -> None:
        fresh = self._failsafe is None or self._failsafe_predicted
        self._armed = False
        self._failsafe = reason
        self._failsafe_predicted = predicted
        self._setpoint = None
        if fresh:
            self._events.append(FailsafeEntered(reason, predicted))

    def _on_pong(self, msg: Pong, now: float) -> None:
        sent = self._pings.pop(msg.host_time_us, None)
        if sent is None:
            return
        self._n.pongs_received += 1
        if self._state is not LinkState.OPEN:
            return
        self._n.rtts.append(now - sent)
        self._n.rtt_count += 1
        self.clock.add(sent, now, msg.mcu_time_us)

    def _on_identity(self, msg: Identity, now: float) -> None:
        self._identities_seen += 1
        if msg.protocol_version != PROTOCOL_VERSION or msg.spec_hash != SPEC_HASH:
            if self._state is not LinkState.CLOSED:
                self._incompatible(msg)
            return
        if msg.reason is IdentityReason.BOOT:
            if self._state is LinkState.OPEN and msg.boot_id != self.boot_id:
                self._session_lost(now, msg.boot_id, "the board announced a new boot")  # sends HELLO
            elif self._state is LinkState.CONNECTING:
                self._send_hello(now)  # answer the announcement at once: ready one round trip after boot
            return
        if msg.reason is IdentityReason.HELLO_REJECTED:
            if msg.hello_seq in self._hello_seqs:
                self._incompatible(msg)
            return
        ours = self._hello_seqs.pop(msg.hello_seq, None) is not None
        if self._state is LinkState.CONNECTING:
            if not ours:
                return  # an answer to someone else's HELLO
            self._open(msg, now)
        elif self._state is LinkState.OPEN:
            if msg.boot_id != self.boot_id:
                self._session_lost(now, msg.boot_id, "an IDENTITY names a new boot")
                return
            # The board re-opened the session (a HELLO of ours that crossed the first answer):
            # it is disarmed and its duplicate memory is cleared.
            self._identity = RobotIdentity.of(msg, now)
            if self._armed:
                self._armed = False
                self._setpoint = None

    def _open(self, msg: Identity, now: float) -> None:
        reconnect = self._opened_once
        self._identity = RobotIdentity.of(msg, now)
        self._state = LinkState.OPEN
        self._opened_s = now
        self._armed = False
        self._failsafe = None
        self._failsafe_predicted = False
        self._config_fresh = False
        self._ready_announced = False
        self._next_ping = now + 0.02
        self._feedback.new_boot()
        if reconnect:
            self._n.reconnects += 1
        self._opened_once = True
        self._events.append(Opened(self._identity, reconnect))
        if self._rearm_after_open:
            self._rearm_after_open = False
            o = self.options
            self._queue.appendleft(Request(Arm(boot_id=msg.boot_id), o.request_tries, o.request_timeout_s, None, True))
        self._pump_queue(now)

    def _refresh_config(self, now: float) -> None:
        """The GET_CONFIG behind the HELLO normally answers in the same round trip; ask again if not."""
        if self._config_fresh or self._opened_s is None or now < self._opened_s + self.options.request_timeout_s:
            return
        pending = [*self._queue, *([self._inflight] if self._inflight else [])]
        if not any(isinstance(r.msg, GetConfig) for r in pending):
            o = self.options
            self._queue.appendleft(Request(GetConfig(), o.request_tries, o.request_timeout_s, None, True))

    def _check_ready(self, now: float) -> None:
        if self._state is LinkState.OPEN and self._config_fresh and not self._ready_announced:
            self._ready_announced = True
            if self.ready_s is None:
                self.ready_s = now
            self._events.append(Ready())

    def _incompatible(self, msg: Identity) -> None:
        self._state = LinkState.INCOMPATIBLE
        self._armed = False
        self._setpoint = None
        o = self.options
        self._error = IncompatibleFirmwareError(
            o.url, msg.protocol_version, msg.spec_hash, PROTOCOL_VERSION, SPEC_HASH, robot_name=msg.robot_name
        )
        for req in [*self._queue, *([self._inflight] if self._inflight else [])]:
            if not req.done:
                self._finish(req, None, self._error)
        self._queue.clear()
        self._inflight = None
        self._events.append(Failed(self._error))

    def _session_lost(self, now: float, new_boot_id: int | None, why: str) -> None:
        """The board's session with us is gone (reset, brown-out, or closed): start again."""
        if self._state is not LinkState.OPEN:
            return
        old = self.boot_id or 0
        self._n.resets_detected += 1
        was_armed = self._armed or self._failsafe is not None or self._setpoint is not None
        self._armed = False
        self._failsafe = None
        self._failsafe_predicted = False
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
        self._feedback.new_boot()  # keep the pose, re-anchor the counts
        self._rx_seq = None
        self._hello_seqs.clear()
        self._handshake_config_seqs.clear()
        self._last_reliable_key = None
        self._state = LinkState.CONNECTING
        self._next_hello = now
        if self.options.auto_rearm and was_armed:
            self._rearm_after_open = True
        else:
            self._reset_pending = (old, new_boot_id, why)
        self._events.append(ResetDetected(old, new_boot_id, why))
        self._send_hello(now)

    def _on_feedback(self, msg: Feedback, now: float) -> None:
        # The receive path's per-frame work: status bits tested as plain ints (IntFlag operators
        # cost a microsecond each), the rest in FeedbackTracker.sample.
        if self._state is not LinkState.OPEN:
            return
        identity = self._identity
        if identity is None or msg.boot_id != identity.boot_id:
            self._rx_seq = None  # a new boot numbers its frames from 0 again
            self._session_lost(now, msg.boot_id, "FEEDBACK carries a new boot_id")
            return
        status = int(msg.status)
        if not status & _SESSION:
            self._session_lost(now, msg.boot_id, "the board reports no session")
            return
        self._n.feedback_received += 1
        self._last_feedback_s = now
        if status & _FAILSAFE:
            self._enter_failsafe(msg.failsafe_reason, predicted=False)
        elif status & _ARMED:
            if not self._armed and self._failsafe is None:
                self._armed = True  # an ARM whose ACK was lost was applied all the same
        elif self._armed:
            self._armed = False
            self._setpoint = None
        sample = self._feedback.sample(msg, now, self.clock)
        self._latest = sample
        self._events.append(FeedbackReceived(sample))


def _nack_error(request: Message | type[Message], nack: Nack) -> NackError:
    """The NackError for a refused request: the field named by a field-index detail, and the value
    sent in it when `request` is the message itself (a class: the value is not known)."""
    field_name: str | None = None
    cls = BY_ID.get(nack.req_id, request if isinstance(request, type) else type(request))
    sent = ""
    if nack.reason in (NackReason.OUT_OF_RANGE, NackReason.INVALID_CONFIG) and nack.detail < len(cls.FIELDS):
        field_name = cls.FIELDS[nack.detail].name
        if nack.reason is NackReason.OUT_OF_RANGE and isinstance(request, cls):
            sent = f"sent {field_name} = {getattr(request, field_name)!r}"
    hints = {
        NackReason.OUT_OF_RANGE: sent,
        NackReason.ARMED: "disarm first (robot.disarm())",
        NackReason.EEPROM_ERROR: "the board's EEPROM did not verify; it may be worn out",
        NackReason.UNSUPPORTED: "this firmware build cannot do that",
        NackReason.INVALID_CONFIG: "fields are in range but inconsistent (steering min <= centre <= max, "
        "servo min < max, ESC min < neutral < max)",
    }
    return NackError(request.NAME, nack.reason, nack.detail, field_name, hints.get(nack.reason, ""))
