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

Its parts each keep their own state and read alone (docs/sdk.md has the full semantics):

    handshake.py   HELLO + GET_CONFIG until an IDENTITY answers; the board's identity and config
    lifecycle.py   the link's state; a session opens, a reset ends it, incompatible firmware, close
    receive.py     what each frame from the board does
    reliable.py    reliable requests: one in flight, retried with the same seq, ACK/NACK/data
    setpoints.py   latest wins, repeated while live, then quiet so the board's watchdog acts
    arming.py      armed, or a latched failsafe (reported by the board or predicted)
    pings.py       time sync: PING/PONG into a least-squares ClockSync
    feedback.py    FEEDBACK -> FeedbackSample: counters unwrapped, odometry advanced
    wire.py        frames out (numbered, counted) and in (decoded, seq gaps counted)
    counters.py    the host's counts and the LinkStatistics snapshot
"""

from __future__ import annotations

from host_sdk.errors import ConnectTimeoutError, NotArmedError, RoverLinkError, SessionResetError
from host_sdk.framing import Frame, FrameDecoder
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.pose import Pose
from host_sdk.session.arming import Arming
from host_sdk.session.counters import HostCounters, link_statistics
from host_sdk.session.events import Event
from host_sdk.session.feedback import FeedbackTracker
from host_sdk.session.handshake import Handshake
from host_sdk.session.lifecycle import Lifecycle, Parts
from host_sdk.session.options import LinkState, SessionOptions
from host_sdk.session.pings import TimeSync
from host_sdk.session.receive import Receiver
from host_sdk.session.reliable import RequestQueue
from host_sdk.session.requests import Request
from host_sdk.session.setpoints import SetpointKeeper
from host_sdk.session.types import FeedbackSample, LinkStatistics, RobotIdentity
from host_sdk.session.wire import Wire
from host_sdk.timesync import ClockSync
from protocol.codec.message import Message
from protocol.generated.constants import CONTROL_RATE_HZ
from protocol.generated.enums import Capability, FailsafeReason, FeedbackMode
from protocol.generated.messages import GetConfig, SetAckermann, SetConfig, SetWheelSpeeds


class Session:
    """The host side of one link (it outlives board resets: each reset opens a new firmware session).

    It makes the parts, wires them together and is their only public face: everything the robot
    does or reads goes through its methods and read-only properties."""

    def __init__(self, options: SessionOptions, kinematics: DiffDrive | Ackermann | None = None) -> None:
        self.options = options
        self._events: list[Event] = []
        self._n = HostCounters()
        self._wire = wire = Wire(self._n)
        self._handshake = handshake = Handshake(options, wire, self._n)
        self._sync = TimeSync(options, wire, self._n)
        self._setpoints = SetpointKeeper(options, wire, self._n)
        self._arming = Arming(self._emit)
        self._feedback = FeedbackTracker(kinematics)
        # The queue asks whether the link is open only once running, after _life is made below.
        self._requests = RequestQueue(
            options,
            wire,
            self._n,
            link_open=lambda: self._life.state is LinkState.OPEN,
            boot_id=lambda: handshake.boot_id,
            burn_seq=self._sync.send_ping,
            emit=self._emit,
            on_send=self._setpoints.request_sent,
            silence_deadline=self.silence_deadline,
        )
        parts = Parts(
            options=options,
            counters=self._n,
            wire=wire,
            handshake=handshake,
            sync=self._sync,
            setpoints=self._setpoints,
            arming=self._arming,
            requests=self._requests,
            feedback=self._feedback,
            emit=self._emit,
        )
        self._life = Lifecycle(parts)
        self._receiver = Receiver(parts, self._life)

    # == inputs ===================================================================================
    def start(self, now: float) -> None:
        """Begin the handshake: the first HELLO goes out now."""
        self._life.start(now)
        self.poll(now)

    def receive(self, data: bytes, now: float) -> None:
        """Bytes from the board."""
        if not data or self._life.state is LinkState.CLOSED:
            return
        frame = self._receiver.frame
        for event in self._wire.decoder.feed(data):
            if isinstance(event, Frame):
                frame(event.message, event.seq, now)

    def poll(self, now: float) -> None:
        """Run the timers: HELLO repeats, request retries, keep-alives, PINGs."""
        state = self._life.state
        if state is LinkState.CONNECTING:
            if self._handshake.hello_due(now):
                self._life.hello(now)
            self._requests.expire(now)
            return
        if state is not LinkState.OPEN:
            return
        self._requests.expire(now)
        self._refresh_config(now)
        self._requests.pump(now)
        self._setpoints.keep_alive(now, self._arming.armed, self._pace_s())
        self._arming.predict_failsafe(now - self._wire.last_tx, self.watchdog_s)
        if self._sync.due(now):
            if self._arming.armed and not self._setpoints.live:
                self._sync.postpone(now)  # armed with no live command: feed no watchdog
            else:
                self._sync.send_ping(now)

    def next_deadline(self, now: float) -> float:
        """The latest time `poll` must run again (a runner may call it earlier)."""
        t = now + 0.05
        state = self._life.state
        if state is LinkState.CONNECTING:
            t = min(t, self._handshake.next_hello)
        retry = self._requests.deadline
        if retry is not None:
            t = min(t, retry)
        if state is LinkState.OPEN:
            t = self._setpoints.deadline(min(t, self._sync.next_ping), self._pace_s())
            if self._arming.armed:
                t = min(t, self._wire.last_tx + self.watchdog_s + 0.02)
        return t

    # == user operations ===========================================================================
    def command(self, msg: SetWheelSpeeds | SetAckermann, now: float, hold_s: float | None = None) -> int:
        """Send a setpoint now and keep it live for `hold_s` (default: command_timeout). Returns its seq.
        Paced lockstep: a setpoint replacing a live one goes out at the next slot instead."""
        return self._setpoints.command(msg, now, hold_s, self._pace_s())

    def release(self) -> None:
        """Stop repeating the current setpoint (the board keeps it until the watchdog)."""
        self._setpoints.drop()

    def stop(self, now: float) -> int | None:
        """Zero speed (steering centred) while armed; else only stop repeating the last setpoint.
        Returns the stop setpoint's seq, if one was sent."""
        if not (self._arming.armed and self._life.state is LinkState.OPEN):
            self._setpoints.drop()
            return None
        identity = self._handshake.identity
        caps = identity.capabilities if identity is not None else Capability(0)
        zero = SetWheelSpeeds(0, 0) if caps & Capability.DIFF_DRIVE else SetAckermann(0, 0)
        return self.command(zero, now)

    def submit(self, msg: Message, now: float, *, tries: int | None = None, timeout_s: float | None = None) -> Request:
        """Queue a reliable request; it is sent when the session is open and none is in flight."""
        return self._requests.submit(msg, now, tries, timeout_s)

    def cancel(self, req: Request) -> None:
        """Give up on a request (its answer, if it comes, is ignored)."""
        self._requests.cancel(req)

    def close(self) -> None:
        """The robot is closed: nothing more is sent; pending requests fail."""
        self._life.close()

    def fail(self, error: RoverLinkError) -> None:
        """The link under the session failed (`error` says how): the robot is unusable. Everything
        pending fails with `error`, the robot is no longer armed, nothing more is sent."""
        self._life.fail(error)

    def set_kinematics(self, kinematics: DiffDrive | Ackermann | None) -> None:
        """The robot's kinematics for odometry (None: no odometry); a pose already integrated is kept."""
        self._feedback.set_kinematics(kinematics)

    # == outputs ===================================================================================
    def outgoing(self) -> bytes:
        """Bytes to write to the board, in order (taking them empties the buffer)."""
        return self._wire.take()

    def take_events(self) -> list[Event]:
        events, self._events = self._events, []
        return events

    def stats(self, now: float) -> LinkStatistics:
        connect_time_s = self._handshake.connect_time_s()
        return link_statistics(self._n, self._wire.decoder.stats, self._sync.clock, now, connect_time_s)

    def _emit(self, event: Event) -> None:
        self._events.append(event)

    def _send(self, msg: Message, now: float, seq: int | None = None) -> int:
        """Send a frame past every part (tests use it to move the seq counter on)."""
        return self._wire.send(msg, now, seq)

    def _pace_s(self) -> float | None:
        """Paced lockstep's period (whole control ticks of the granted rate), else None."""
        identity = self._handshake.identity
        if not self.options.paced or identity is None or identity.feedback_mode is not FeedbackMode.LOCKSTEP:
            return None
        ticks = max(1, round(CONTROL_RATE_HZ / (identity.feedback_hz or CONTROL_RATE_HZ)))
        return ticks / CONTROL_RATE_HZ

    def _refresh_config(self, now: float) -> None:
        """Ask for the configuration again when the GET_CONFIG behind the HELLO went unanswered."""
        if self._handshake.refresh_due(now) and not self._requests.pending(GetConfig):
            self._requests.push_front(GetConfig())

    # == what the robot asks =======================================================================
    def take_reset(self) -> SessionResetError | None:
        """The SessionResetError to raise on the user's next command (once), if a reset happened."""
        return self._life.take_reset()

    @property
    def reset_pending(self) -> bool:
        """A reset is known and not yet reported to the user."""
        return self._life.reset_pending

    def silence_deadline(self, now: float) -> float | None:
        """When the board has gone quiet while the session is open (nothing at all heard for three
        FEEDBACK periods; lockstep while armed, when FEEDBACK answers setpoints only: for a request
        timeout): the time until which that silence may still end in a boot announcement,
        `reset_silence_s` after the last frame (a reset in its bootloader; past already when it has
        been silent longer). None while the board talks."""
        last = self._wire.last_rx
        if self._life.state is not LinkState.OPEN or last is None:
            return None
        identity = self._handshake.identity
        quiet = self.options.request_timeout_s
        # A lockstep board streams too while it is not armed.
        streaming = identity is not None and (identity.feedback_mode is FeedbackMode.STREAM or not self.armed)
        if identity is not None and streaming and identity.feedback_hz:
            quiet = max(0.05, 3 / identity.feedback_hz)
        if now - last < quiet:
            return None
        return last + self.options.reset_silence_s

    def take_command_error(self) -> RoverLinkError | None:
        """What the user's next drive command must raise, once: a reset not yet reported, or a
        setpoint the board refused."""
        error: RoverLinkError | None = self.take_reset()
        if error is None:
            error = self._setpoints.take_refusal()
        return error

    def not_armed_error(self) -> NotArmedError:
        """The error for a drive command while not armed, saying why and what to do."""
        reopening = self._life.state is LinkState.CONNECTING
        return self._arming.not_armed_error(reopening, self.watchdog_s, self.options.command_timeout)

    def wants_rearm(self) -> bool:
        """Not armed, and nothing but a reset or a watchdog failsafe keeps it so (auto_rearm's cue)."""
        return self._arming.wants_rearm()

    def connect_timeout_error(self, timeout_s: float) -> ConnectTimeoutError:
        """Why no session opened within `timeout_s`, from what was heard."""
        return self._handshake.connect_timeout_error(timeout_s)

    def esc_window_left(self, now: float) -> float:
        """Seconds until an ESC robot's power-up arming window ends (0 without an ESC)."""
        return self._handshake.esc_window_left(now)

    def pose(self) -> Pose | None:
        """The odometry's pose (None without kinematics)."""
        return self._feedback.pose()

    def reset_pose(self, x_m: float, y_m: float, theta_rad: float) -> bool:
        """Set the pose (counting goes on from the next sample); False without kinematics."""
        return self._feedback.reset_pose(x_m, y_m, theta_rad)

    def mcu_to_host_s(self, mcu_time_us: float) -> float:
        """Host time of an unwrapped MCU timestamp (PING/PONG time sync)."""
        return self._sync.clock.to_host_s(mcu_time_us)

    # == state (read-only: the session changes it, nothing else) ===================================
    @property
    def state(self) -> LinkState:
        return self._life.state

    @property
    def identity(self) -> RobotIdentity | None:
        """The IDENTITY that opened the current session."""
        return self._handshake.identity

    @property
    def config(self) -> SetConfig | None:
        """The board's configuration as last read or written."""
        return self._handshake.config

    @property
    def armed(self) -> bool:
        return self._arming.armed

    @property
    def failsafe(self) -> FailsafeReason | None:
        """Latched FAILSAFE the board reported (or the host predicted); None when not in failsafe."""
        return self._arming.failsafe

    @property
    def error(self) -> RoverLinkError | None:
        """Why the session cannot go on (incompatible firmware, a broken link)."""
        return self._life.error

    @property
    def latest(self) -> FeedbackSample | None:
        """The latest FEEDBACK."""
        return self._feedback.latest

    @property
    def last_feedback_s(self) -> float | None:
        latest = self._feedback.latest
        return latest.received_s if latest is not None else None

    @property
    def kinematics(self) -> DiffDrive | Ackermann | None:
        return self._feedback.kinematics

    @property
    def ready(self) -> bool:
        return self._life.state is LinkState.OPEN and self._handshake.config_fresh

    @property
    def boot_id(self) -> int | None:
        return self._handshake.boot_id

    @property
    def watchdog_s(self) -> float:
        return self._handshake.watchdog_s

    @property
    def feedback_mode(self) -> FeedbackMode:
        return self._handshake.feedback_mode

    @property
    def setpoint_live(self) -> bool:
        return self._setpoints.live

    @property
    def last_setpoint_seq(self) -> int:
        return self._setpoints.last_seq

    @property
    def clock(self) -> ClockSync:
        """The PING/PONG time sync (MCU time -> host time)."""
        return self._sync.clock

    @property
    def decoder(self) -> FrameDecoder:
        return self._wire.decoder

    @property
    def started_s(self) -> float | None:
        """When the handshake began."""
        return self._handshake.started_s

    @property
    def ready_s(self) -> float | None:
        """When the session was first ready."""
        return self._handshake.ready_s
