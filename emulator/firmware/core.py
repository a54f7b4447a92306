"""The firmware model: frame handling, reliable requests, setpoints, the control tick and boot.

Written from docs/control.md (normative) and docs/protocol.md; section numbers in comments refer to
docs/control.md. The session's transitions come only from the generated table (see session.py);
this module performs the actions of the row that fired.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

from emulator.firmware.board import Board
from emulator.firmware.config import (
    BOOT_COUNTER_ADDR,
    IMAGE_ADDR,
    IMAGE_SIZE,
    Gains,
    LoadResult,
    decode_image,
    first_out_of_range,
)
from emulator.firmware.lights import lights_now, power_up
from emulator.firmware.link import BadValue, FirmwareLink
from emulator.firmware.requests import REQUESTS, ack, nack
from emulator.firmware.session import ACTION_ORDER, Session
from emulator.firmware.statemachine import Action, Guard, SessionEvent, SessionState
from emulator.firmware.tick import RAMP_UNITS, ControlTick, Pending, clamp, wrap_i32
from emulator.truth import FirmwareTruth
from protocol.codec.message import Direction, Message
from protocol.framing import Frame
from protocol.generated.constants import (
    FEEDBACK_HZ_MAX,
    LOCKSTEP_QUEUE,
    PROTOCOL_VERSION,
    SPEC_HASH,
    WATCHDOG_MAX_MS,
    WATCHDOG_MIN_MS,
    WHEEL_COUNT,
)
from protocol.generated.enums import (
    Board as BoardId,
)
from protocol.generated.enums import (
    Capability,
    FailsafeReason,
    FeedbackMode,
    IdentityReason,
    LogLevel,
    NackReason,
)
from protocol.generated.messages import (
    Ack,
    Arm,
    Disarm,
    Hello,
    Identity,
    Log,
    Nack,
    Ping,
    Pong,
    SetAckermann,
    SetConfig,
    SetWheelSpeeds,
)
from protocol.generated.profiles import RobotProfile
from protocol.generated.version import VERSION as FIRMWARE_VERSION

BOOT_COUNTER_BYTES = 4
_U32 = 1 << 32


@dataclass(slots=True)
class _Ctx:
    """What the actions of one row need to know about the frame that fired it."""

    msg: Message | None = None
    seq: int = 0
    nack: NackReason = NackReason.NO_SESSION
    nack_detail: int = 0
    reason: FailsafeReason = FailsafeReason.NONE
    reply: Message | None = None


class Firmware(ControlTick):
    """One boot of the firmware. A reset throws the object away (RAM is lost) and builds a new one."""

    def __init__(self, board: Board, robot: RobotProfile, board_id: BoardId = BoardId.EMULATOR) -> None:
        self.board = board
        self.robot = robot
        self.board_id = board_id
        self.caps = robot.capabilities
        self.wheels = 1 if self.caps & Capability.ACKERMANN and not self.caps & Capability.DIFF_DRIVE else 2
        self.session = Session()
        self.link = FirmwareLink()
        self.config: SetConfig = robot.config
        self.gains: list[Gains] = [Gains.of(robot.pid)] * WHEEL_COUNT
        self.config_defaults = False
        self.boot_id = 0
        self.boot_count = 0
        self.boot_micros = 0
        # Session grants (IDLE values until a HELLO is accepted).
        self.watchdog_ms = robot.config.watchdog_ms
        self.feedback_mode = FeedbackMode.STREAM
        self.feedback_hz = robot.config.feedback_hz
        self.last_valid_us = 0
        self.latched = FailsafeReason.NONE
        self._dup: tuple[tuple[int, int], Message | None] | None = None
        self.lights_setting = power_up(robot.lights_mode)
        self.lit = 0
        self._init_control(robot)
        self._handlers: dict[type[Message], Callable[[Message, int], None]] = {
            Hello: self._on_hello,
            Ping: self._on_ping,
            Arm: self._on_arm,
            Disarm: self._on_disarm,
            SetWheelSpeeds: self._on_setpoint,
            SetAckermann: self._on_setpoint,
            **dict.fromkeys(REQUESTS, self._on_request),
        }

    # == boot (6) ==================================================================================
    def setup(self) -> None:
        board = self.board
        self.boot_micros = board.micros()
        # A board without storage (the Pico) boots on the robot's defaults, with no LOG about them
        # and no boot counter, as the C++ core does without Capability.EEPROM.
        storage = bool(self.caps & Capability.EEPROM)
        loaded, config, gains = (
            decode_image(board.eeprom_read(IMAGE_ADDR, IMAGE_SIZE)) if storage else (LoadResult.OK, None, None)
        )
        if config is None or gains is None:
            self.config = self.robot.config
            self.gains = [Gains.of(self.robot.pid)] * WHEEL_COUNT
            self.config_defaults = storage
        else:
            self.config, self.gains = config, gains
        self.watchdog_ms = self.config.watchdog_ms
        self.feedback_hz = self.config.feedback_hz
        self.servo_cdeg = self.config.steering_center_cdeg
        self._fb_countdown = 1  # the first tick after boot streams a FEEDBACK (IDLE)
        self.boot_count = 0
        if storage:
            stored = int.from_bytes(board.eeprom_read(BOOT_COUNTER_ADDR, BOOT_COUNTER_BYTES), "little")
            self.boot_count = (0 if stored == 0xFFFFFFFF else stored) + 1
            data = (self.boot_count & 0xFFFFFFFF).to_bytes(BOOT_COUNTER_BYTES, "little")
            board.eeprom_write(BOOT_COUNTER_ADDR, data)
        self.boot_id = _mix_boot_id(self.boot_count, board.entropy())
        # The ESC sees neutral from boot and the servo its centre (its arming window starts now).
        self._write_outputs(driving=False)
        self._fire(SessionEvent.INIT_DONE)
        if loaded is not LoadResult.OK:
            self._send(Log(LogLevel.WARN, loaded.value))
        # The turn signals show the IDLE pattern from INIT_DONE on, not from the first tick (the
        # C++ core's begin() does the same; found by tests/system/conformance, test_turn_signal_leds).
        if self.caps & Capability.TURN_SIGNALS:
            self.lit = lights_now(self.session.state, self.lights_setting, 0, 0, steer_cdeg=0, ackermann=False, blink=0)
            board.lights(self.lit)

    # == frames (1) ================================================================================
    def on_bytes(self, data: bytes) -> None:
        for event in self.link.feed(data):
            if isinstance(event, BadValue):
                self._on_bad_value(event)
            else:
                self._on_frame(event)

    def _on_frame(self, frame: Frame) -> None:
        msg, seq = frame
        self.link.account_seq(seq)
        self._fire(SessionEvent.VALID_FRAME)
        if msg.DIRECTION is not Direction.HOST_TO_MCU:
            return  # valid but travelling the wrong way: ignored after VALID_FRAME (1.3)
        handler = self._handlers.get(type(msg))
        if handler is not None:
            handler(msg, seq)

    def _on_bad_value(self, bad: BadValue) -> None:
        """1.4: a reliable request holding a value its type does not define is a valid frame whose
        field is out of range: the request's rules, then NACK(OUT_OF_RANGE, detail = the field)."""
        self.link.account_seq(bad.seq)
        self._fire(SessionEvent.VALID_FRAME)

        def apply() -> Message | None:
            if self.session.state is SessionState.IDLE or self.session.state is SessionState.BOOT:
                reply = nack(bad.request, bad.seq, NackReason.NO_SESSION)
            else:
                reply = nack(bad.request, bad.seq, NackReason.OUT_OF_RANGE, bad.field)
            self._send(reply)
            return reply

        self._reliable(bad.request, bad.seq, apply)

    def _on_hello(self, msg: Message, seq: int) -> None:
        assert isinstance(msg, Hello)
        compatible = msg.protocol_version == PROTOCOL_VERSION and msg.spec_hash == SPEC_HASH
        self._fire(SessionEvent.HELLO, lambda g: g is Guard.COMPATIBLE and compatible, _Ctx(msg, seq))

    def _on_ping(self, msg: Message, seq: int) -> None:
        assert isinstance(msg, Ping)
        self._send(Pong(host_time_us=msg.host_time_us, mcu_time_us=self.board.micros()))

    def _on_arm(self, msg: Message, seq: int) -> None:
        assert isinstance(msg, Arm)

        def apply() -> Message | None:
            nack = NackReason.NO_SESSION if self.session.state is SessionState.IDLE else NackReason.BOOT_ID_MISMATCH
            ctx = _Ctx(msg, seq, nack=nack)
            matches = msg.boot_id == self.boot_id
            self._fire(SessionEvent.ARM, lambda g: g is Guard.BOOT_ID_MATCHES and matches, ctx)
            return ctx.reply

        self._reliable(msg, seq, apply)

    def _on_disarm(self, msg: Message, seq: int) -> None:
        def apply() -> Message | None:
            ctx = _Ctx(msg, seq)
            self._fire(SessionEvent.DISARM, None, ctx)
            return ctx.reply

        self._reliable(msg, seq, apply)

    # == reliable requests (2) =====================================================================
    def _reliable(
        self, msg: Message | type[Message], seq: int, apply: Callable[[], Message | None], fresh: bool = False
    ) -> None:
        """Duplicate rule: the same (msg_id, seq) as the last reliable request is answered again
        (a fresh reply for GET_*, else the same ACK/NACK) and not applied again."""
        key = (msg.MSG_ID, seq)
        if self._dup is not None and self._dup[0] == key:
            self.link.counts.duplicates += 1
            answer = self._dup[1]
            if answer is None:
                apply()  # GET_*: a fresh reply with the current values; reading changes nothing
            else:
                self._send(answer)
            return
        reply = apply()
        keep = None if fresh and not isinstance(reply, (Ack, Nack)) else reply
        self._dup = (key, keep)

    def _on_request(self, msg: Message, seq: int) -> None:
        """A reliable request of REQUESTS: refused outside a session, else applied; answered once,
        and again (not re-applied) for a duplicate."""
        request = REQUESTS[type(msg)]

        def apply() -> Message | None:
            if self.session.state is SessionState.IDLE or self.session.state is SessionState.BOOT:
                reply: Message = nack(msg, seq, NackReason.NO_SESSION)
            else:
                reply = request.apply(self, msg, seq)
            self._send(reply)
            return reply

        self._reliable(msg, seq, apply, fresh=request.fresh)

    def set_gains(self, wheels: Iterable[int], gains: Gains) -> None:
        """SET_PID: the next tick uses the gains and resets these wheels' integrators."""
        for w in wheels:
            self.gains[w] = gains
            self._reset_integrator[w] = True

    def set_config(self, config: SetConfig) -> None:
        """SET_CONFIG (validated): counts are reported after encoder_invert, so a flipped wheel's
        baseline flips too and its speed measurement stays continuous."""
        flipped = self.config.encoder_invert ^ config.encoder_invert
        for w in range(WHEEL_COUNT):
            if flipped >> w & 1:
                self.counts[w] = wrap_i32(-self.counts[w])
        self.config = config

    # == setpoints (3) =============================================================================
    def _on_setpoint(self, msg: Message, seq: int) -> None:
        needed = Capability.DIFF_DRIVE if isinstance(msg, SetWheelSpeeds) else Capability.ACKERMANN
        if not self.caps & needed:
            self._nack(msg, seq, NackReason.UNSUPPORTED)
            return
        state = self.session.state
        nack = {
            SessionState.DISARMED: NackReason.NOT_ARMED,
            SessionState.FAILSAFE: NackReason.FAILSAFE,
        }.get(state, NackReason.NO_SESSION)
        detail = int(self.latched) if nack is NackReason.FAILSAFE else 0
        self._fire(SessionEvent.SETPOINT, None, _Ctx(msg, seq, nack=nack, nack_detail=detail))

    def _apply_setpoint(self, ctx: _Ctx) -> None:
        msg, seq = ctx.msg, ctx.seq
        limit = self.config.max_wheel_speed_mm_s
        if isinstance(msg, SetWheelSpeeds):
            speeds = (msg.left_mm_s, msg.right_mm_s)
        elif isinstance(msg, SetAckermann):
            speeds = (msg.speed_mm_s, 0)
        else:  # pragma: no cover - only setpoints fire SETPOINT
            return
        # The first speed over the limit or the first field outside its spec range, whichever
        # comes first in the message.
        bad = [i for i, v in enumerate(speeds) if abs(v) > limit]
        spec = first_out_of_range(msg)
        if spec is not None:
            bad.append(spec)
        if bad:
            self._nack(msg, seq, NackReason.OUT_OF_RANGE, min(bad))
            return
        steer = msg.steering_mrad if isinstance(msg, SetAckermann) else None
        # Stream mode: latest wins. Lockstep: queued, so a host may stay a tick ahead; full, the
        # newest is superseded.
        room = LOCKSTEP_QUEUE if self.feedback_mode is FeedbackMode.LOCKSTEP else 1
        if len(self.pending) >= room:
            self.pending.pop()
        self.pending.append(Pending(seq, (speeds[0], speeds[1]), steer))

    def _failsafe(self, event: SessionEvent, reason: FailsafeReason) -> None:
        self._fire(event, None, _Ctx(reason=reason))

    # == the state machine and its actions =========================================================
    def _fire(self, event: SessionEvent, guard: Callable[[Guard], bool] | None = None, ctx: _Ctx | None = None) -> None:
        row = self.session.fire(event, guard)
        if row is None:
            return
        ctx = ctx or _Ctx()
        for action in ACTION_ORDER:
            if row.actions & action:
                self._perform(action, ctx)

    def _perform(self, action: Action, ctx: _Ctx) -> None:
        if action is Action.MOTORS_SAFE:
            self._motors_safe()
        elif action is Action.CLEAR_REASON:
            self.latched = FailsafeReason.NONE
            self.encoder_fault = [False] * WHEEL_COUNT
            self.stall_ticks = [0] * WHEEL_COUNT
        elif action is Action.LATCH_REASON:
            self.latched = ctx.reason
        elif action is Action.FEED_WATCHDOG:
            self.last_valid_us = self.board.micros()
        elif action is Action.MOTORS_ENABLE:
            self.stall_ticks = [0] * WHEEL_COUNT  # the tick drives from setpoints while ARMED
        elif action is Action.APPLY_SETPOINT:
            self._apply_setpoint(ctx)
        elif action is Action.ACCEPT_HELLO:
            self._accept_hello(ctx)
        elif action is Action.REJECT_HELLO:
            self._reject_hello(ctx)
        elif action is Action.ANNOUNCE:
            self._send(self._identity(IdentityReason.BOOT, 0))
        elif action is Action.ACK:
            assert ctx.msg is not None
            ctx.reply = self._ack(ctx.msg, ctx.seq)
        elif action is Action.NACK:
            assert ctx.msg is not None
            ctx.reply = self._nack(ctx.msg, ctx.seq, ctx.nack, ctx.nack_detail)

    def _accept_hello(self, ctx: _Ctx) -> None:
        msg = ctx.msg
        assert isinstance(msg, Hello)
        c = self.config
        self.watchdog_ms = clamp(msg.watchdog_ms or c.watchdog_ms, WATCHDOG_MIN_MS, WATCHDOG_MAX_MS)
        # LOCKSTEP only where the build has the capability, as the C++ core does; otherwise STREAM
        # (the SDK reads the granted mode from IDENTITY and refuses the session then).
        wants_lockstep = msg.feedback_mode is FeedbackMode.LOCKSTEP
        lockstep_ok = bool(self.caps & Capability.LOCKSTEP)
        self.feedback_mode = FeedbackMode.LOCKSTEP if wants_lockstep and lockstep_ok else FeedbackMode.STREAM
        self.feedback_hz = clamp(msg.feedback_hz or c.feedback_hz, 1, FEEDBACK_HZ_MAX)
        self._dup = None
        self.lights_setting = power_up(self.robot.lights_mode)  # nothing of the last host's stays
        self.link.restart_seq_accounting()
        self._fb_countdown = 1  # the first FEEDBACK of the session comes at the next tick
        self._send(self._identity(IdentityReason.HELLO_ACCEPTED, ctx.seq))

    def _reject_hello(self, ctx: _Ctx) -> None:
        self.watchdog_ms = self.config.watchdog_ms
        self.feedback_mode = FeedbackMode.STREAM
        self.feedback_hz = self.config.feedback_hz
        self._fb_countdown = 1
        self._send(self._identity(IdentityReason.HELLO_REJECTED, ctx.seq))

    def _identity(self, reason: IdentityReason, hello_seq: int) -> Identity:
        uptime_ms = ((self.board.micros() - self.boot_micros) % _U32) // 1000
        return Identity(
            protocol_version=PROTOCOL_VERSION,
            spec_hash=SPEC_HASH,
            firmware_version=FIRMWARE_VERSION,
            board=self.board_id,
            capabilities=self.caps,
            boot_id=self.boot_id,
            uptime_ms=uptime_ms,
            reason=reason,
            hello_seq=hello_seq,
            watchdog_ms=self.watchdog_ms,
            feedback_mode=self.feedback_mode,
            feedback_hz=self.feedback_hz,
            robot_name=self.robot.example[:24],
        )

    def _ack(self, msg: Message | type[Message], seq: int) -> Ack:
        reply = ack(msg, seq)
        self._send(reply)
        return reply

    def _nack(self, msg: Message | type[Message], seq: int, reason: NackReason, detail: int = 0) -> Nack:
        reply = nack(msg, seq, reason, detail)
        self._send(reply)
        return reply

    def _send(self, msg: Message) -> None:
        self.board.serial_write(self.link.encode(msg))

    # == ground truth ==============================================================================
    def snapshot(self) -> FirmwareTruth:
        return FirmwareTruth(
            state=self.session.state,
            boot_id=self.boot_id,
            boot_count=self.boot_count,
            micros=self.board.micros(),
            tick=self.tick_count,
            watchdog_ms=self.watchdog_ms,
            feedback_mode=self.feedback_mode,
            feedback_hz=self.feedback_hz,
            failsafe_reason=self.latched,
            status=self.status(),
            config=self.config,
            gains=tuple(self.gains),
            config_defaults=self.config_defaults,
            targets_mm_s=tuple(float(t) for t in self.targets),
            ramped_mm_s=tuple(r / RAMP_UNITS for r in self.ramped_units),
            measured_mm_s=tuple(self.measured),
            efforts_permille=tuple(self.efforts),
            integrals=tuple(p.integral for p in self.pids),
            encoder_counts=tuple(self.counts),
            encoder_fault=tuple(self.encoder_fault),
            ack_seq=self.ack_seq,
            ack_tick=self.ack_tick,
            steering_cdeg=self.servo_cdeg,
            esc_hold=self._esc_hold(self.board.micros()),
            last_valid_frame_us=self.last_valid_us,
            link=self.link.stats(),
            transitions=tuple(self.session.history),
        )


def _mix_boot_id(counter: int, entropy: int) -> int:
    """32 bits from the boot counter and physical noise (a murmur3 finaliser); never 0."""
    x = (counter * 0x9E3779B1 ^ entropy) & 0xFFFFFFFF
    x ^= x >> 16
    x = (x * 0x85EBCA6B) & 0xFFFFFFFF
    x ^= x >> 13
    x = (x * 0xC2B2AE35) & 0xFFFFFFFF
    x ^= x >> 16
    return x or 1
