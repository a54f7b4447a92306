"""The firmware model: frame handling, reliable requests, setpoints, the control tick and boot.

Written from docs/control.md (normative) and docs/protocol.md; section numbers in comments refer to
docs/control.md. The session's transitions come only from the generated table (see session.py);
this module performs the actions of the row that fired.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass

from emulator.firmware.board import Board
from emulator.firmware.config import (
    BOOT_COUNTER_ADDR,
    IMAGE_ADDR,
    IMAGE_SIZE,
    Gains,
    LoadResult,
    decode_image,
    encode_image,
    first_inconsistent,
    first_out_of_range,
    pid_wheel_ok,
)
from emulator.firmware.control import WheelPid, ramp_step, round_half_away
from emulator.firmware.lights import BLINK_PERIOD_TICKS, light_mask
from emulator.firmware.link import BadValue, FirmwareLink
from emulator.firmware.session import ACTION_ORDER, Session
from emulator.firmware.statemachine import Action, Guard, SessionEvent, SessionState
from emulator.plant.motor import DriveMode
from emulator.truth import FirmwareTruth
from protocol.codec.message import Direction, Message
from protocol.framing import Frame
from protocol.generated.constants import (
    CONTROL_RATE_HZ,
    FEEDBACK_HZ_MAX,
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
    SafeState,
    Status,
)
from protocol.generated.messages import (
    Ack,
    Arm,
    Config,
    Disarm,
    Feedback,
    GetConfig,
    GetLinkStats,
    GetPid,
    Hello,
    Identity,
    LinkStats,
    Log,
    Nack,
    Pid,
    Ping,
    Pong,
    ResetOdometry,
    SaveConfig,
    SetAckermann,
    SetConfig,
    SetPid,
    SetWheelSpeeds,
)
from protocol.generated.profiles import RobotProfile

FIRMWARE_VERSION = (0, 1, 0)
DT_S = 1.0 / CONTROL_RATE_HZ
TICK_US = 1_000_000 // CONTROL_RATE_HZ
ENCODER_FAULT_EFFORT = 300
ENCODER_FAULT_TICKS = 50
BOOT_COUNTER_BYTES = 4
RAMP_UNITS = 100
"""Ramp resolution: units per mm/s."""
_U32 = 1 << 32


def wrap_i32(x: int) -> int:
    return (x + (1 << 31)) % _U32 - (1 << 31)


def _clamp(x: int, lo: int, hi: int) -> int:
    return lo if x < lo else hi if x > hi else x


@dataclass(slots=True)
class _Pending:
    """A setpoint accepted in ARMED and waiting for the next tick (latest wins)."""

    seq: int
    targets: tuple[int, int]
    servo_cdeg: int | None


@dataclass(slots=True)
class _Ctx:
    """What the actions of one row need to know about the frame that fired it."""

    msg: Message | None = None
    seq: int = 0
    nack: NackReason = NackReason.NO_SESSION
    nack_detail: int = 0
    reason: FailsafeReason = FailsafeReason.NONE
    reply: Message | None = None


class Firmware:
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
        # Control state.
        self.tick_count = 0
        self.counts = [0] * WHEEL_COUNT
        self.deltas = [0] * WHEEL_COUNT
        self.measured = [0] * WHEEL_COUNT
        self.targets = [0] * WHEEL_COUNT
        self.ramped_units = [0] * WHEEL_COUNT
        """Ramped setpoints in 0.01 mm/s."""
        self.efforts = [0] * WHEEL_COUNT
        self.pids = [WheelPid() for _ in range(WHEEL_COUNT)]
        self.saturated = False
        self.pending: _Pending | None = None
        self.ack_seq = 0
        self.ack_tick = 0
        self.servo_cdeg = robot.config.steering_center_cdeg
        self.stall_ticks = [0] * WHEEL_COUNT
        self.encoder_fault = [False] * WHEEL_COUNT
        self._reset_integrator = [False] * WHEEL_COUNT
        self._fb_countdown = 1
        self._blink = 0
        self._esc_armed = False
        """The ESC's arming window is over (latched by the first tick after it)."""
        self.sent_feedback = 0
        self._handlers: dict[type[Message], Callable[[Message, int], None]] = {
            Hello: self._on_hello,
            Ping: self._on_ping,
            Arm: self._on_arm,
            Disarm: self._on_disarm,
            SetPid: self._on_set_pid,
            GetPid: self._on_get_pid,
            SetConfig: self._on_set_config,
            GetConfig: self._on_get_config,
            SaveConfig: self._on_save_config,
            ResetOdometry: self._on_reset_odometry,
            GetLinkStats: self._on_get_link_stats,
            SetWheelSpeeds: self._on_setpoint,
            SetAckermann: self._on_setpoint,
        }

    # == boot (6) ==================================================================================
    def setup(self) -> None:
        board = self.board
        self.boot_micros = board.micros()
        loaded, config, gains = decode_image(board.eeprom_read(IMAGE_ADDR, IMAGE_SIZE))
        if config is None or gains is None:
            self.config = self.robot.config
            self.gains = [Gains.of(self.robot.pid)] * WHEEL_COUNT
            self.config_defaults = True
        else:
            self.config, self.gains = config, gains
        self.watchdog_ms = self.config.watchdog_ms
        self.feedback_hz = self.config.feedback_hz
        self.servo_cdeg = self.config.steering_center_cdeg
        self._fb_countdown = 1  # the first tick after boot streams a FEEDBACK (IDLE)
        stored = int.from_bytes(board.eeprom_read(BOOT_COUNTER_ADDR, BOOT_COUNTER_BYTES), "little")
        self.boot_count = (0 if stored == 0xFFFFFFFF else stored) + 1
        board.eeprom_write(BOOT_COUNTER_ADDR, (self.boot_count & 0xFFFFFFFF).to_bytes(BOOT_COUNTER_BYTES, "little"))
        self.boot_id = _mix_boot_id(self.boot_count, board.entropy())
        # The ESC sees neutral from boot and the servo its centre (its arming window starts now).
        self._write_outputs(driving=False)
        self._fire(SessionEvent.INIT_DONE)
        if loaded is not LoadResult.OK:
            self._send(Log(LogLevel.WARN, loaded.value))
        # The turn signals show the IDLE pattern from INIT_DONE on, not from the first tick (the
        # C++ core's begin() does the same; found by tests/conformance, test_turn_signal_leds).
        if self.caps & Capability.TURN_SIGNALS:
            board.lights(light_mask(self.session.state, 0, 0, steer_cdeg=0, ackermann=False, blink=0))

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
            refused = self._needs_session(bad.request, bad.seq)
            return refused or self._nack(bad.request, bad.seq, NackReason.OUT_OF_RANGE, bad.field)

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
            self.link.duplicates += 1
            answer = self._dup[1]
            if answer is None:
                apply()  # GET_*: a fresh reply with the current values; reading changes nothing
            else:
                self._send(answer)
            return
        reply = apply()
        keep = None if fresh and not isinstance(reply, (Ack, Nack)) else reply
        self._dup = (key, keep)

    def _needs_session(self, msg: Message | type[Message], seq: int) -> Nack | None:
        if self.session.state is SessionState.IDLE or self.session.state is SessionState.BOOT:
            return self._nack(msg, seq, NackReason.NO_SESSION)
        return None

    def _on_set_pid(self, msg: Message, seq: int) -> None:
        assert isinstance(msg, SetPid)

        def apply() -> Message | None:
            refused = self._needs_session(msg, seq)
            if refused is not None:
                return refused
            if not pid_wheel_ok(msg.wheel):
                return self._nack(msg, seq, NackReason.OUT_OF_RANGE, 0)
            bad = first_out_of_range(msg)
            if bad is not None:
                return self._nack(msg, seq, NackReason.OUT_OF_RANGE, bad)
            wheels = range(WHEEL_COUNT) if msg.wheel >= WHEEL_COUNT else (msg.wheel,)
            for w in wheels:
                self.gains[w] = Gains.of(msg)
                self._reset_integrator[w] = True  # the next tick uses the gains and resets this integrator
            return self._ack(msg, seq)

        self._reliable(msg, seq, apply)

    def _on_get_pid(self, msg: Message, seq: int) -> None:
        assert isinstance(msg, GetPid)

        def apply() -> Message | None:
            refused = self._needs_session(msg, seq)
            if refused is not None:
                return refused
            if not 0 <= msg.wheel < WHEEL_COUNT:
                return self._nack(msg, seq, NackReason.OUT_OF_RANGE, 0)
            g = self.gains[msg.wheel]
            reply = Pid(req_seq=seq, wheel=msg.wheel, kp=g.kp, ki=g.ki, kd=g.kd, kf=g.kf)
            self._send(reply)
            return reply

        self._reliable(msg, seq, apply, fresh=True)

    def _on_set_config(self, msg: Message, seq: int) -> None:
        assert isinstance(msg, SetConfig)

        def apply() -> Message | None:
            refused = self._needs_session(msg, seq)
            if refused is not None:
                return refused
            bad = first_out_of_range(msg)
            if bad is not None:
                return self._nack(msg, seq, NackReason.OUT_OF_RANGE, bad)
            bad = first_inconsistent(msg)
            if bad is not None:
                return self._nack(msg, seq, NackReason.INVALID_CONFIG, bad)
            flipped = self.config.encoder_invert ^ msg.encoder_invert
            for w in range(WHEEL_COUNT):
                if flipped >> w & 1:
                    # Counts are reported after encoder_invert: keep the speed measurement continuous.
                    self.counts[w] = wrap_i32(-self.counts[w])
            self.config = msg
            return self._ack(msg, seq)

        self._reliable(msg, seq, apply)

    def _on_get_config(self, msg: Message, seq: int) -> None:
        def apply() -> Message | None:
            refused = self._needs_session(msg, seq)
            if refused is not None:
                return refused
            reply = Config(req_seq=seq, **self.config.fields())
            self._send(reply)
            return reply

        self._reliable(msg, seq, apply, fresh=True)

    def _on_save_config(self, msg: Message, seq: int) -> None:
        def apply() -> Message | None:
            refused = self._needs_session(msg, seq)
            if refused is not None:
                return refused
            if not self.caps & Capability.EEPROM:
                return self._nack(msg, seq, NackReason.UNSUPPORTED)
            if self.session.state is SessionState.ARMED:
                return self._nack(msg, seq, NackReason.ARMED)
            image = encode_image(self.config, self.gains)
            written = self.board.eeprom_write(IMAGE_ADDR, image)
            if not written or self.board.eeprom_read(IMAGE_ADDR, IMAGE_SIZE) != image:
                return self._nack(msg, seq, NackReason.EEPROM_ERROR)
            self.config_defaults = False
            return self._ack(msg, seq)

        self._reliable(msg, seq, apply)

    def _on_reset_odometry(self, msg: Message, seq: int) -> None:
        def apply() -> Message | None:
            refused = self._needs_session(msg, seq)
            if refused is not None:
                return refused
            self.board.zero_encoders()
            self.counts = [0] * WHEEL_COUNT  # the measurement baseline too: no speed spike
            return self._ack(msg, seq)

        self._reliable(msg, seq, apply)

    def _on_get_link_stats(self, msg: Message, seq: int) -> None:
        def apply() -> Message | None:
            refused = self._needs_session(msg, seq)
            if refused is not None:
                return refused
            counters = asdict(self.link.counters())
            names = [f.name for f in LinkStats.FIELDS]
            values = {name: counters.get(name, 0) & 0xFFFFFFFF for name in names if name != "req_seq"}
            reply = LinkStats(req_seq=seq, **values)
            self._send(reply)
            return reply

        self._reliable(msg, seq, apply, fresh=True)

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
        servo = self._servo_cdeg_for(msg.steering_mrad) if isinstance(msg, SetAckermann) else None
        self.pending = _Pending(seq, (speeds[0], speeds[1]), servo)

    def _servo_cdeg_for(self, steering_mrad: int) -> int:
        c = self.config
        center = c.steering_center_cdeg
        cdeg = center + round_half_away(steering_mrad * 18000 / (1000 * math.pi))
        cdeg = _clamp(cdeg, c.steering_min_cdeg, c.steering_max_cdeg)
        if c.steering_step_cdeg > 0:
            step = c.steering_step_cdeg
            cdeg = center + step * round_half_away((cdeg - center) / step)
            cdeg = _clamp(cdeg, c.steering_min_cdeg, c.steering_max_cdeg)
        return cdeg

    def steering_mrad(self) -> int:
        if not self.caps & Capability.STEERING_SERVO:
            return 0
        mrad = round_half_away((self.servo_cdeg - self.config.steering_center_cdeg) * 1000 * math.pi / 18000)
        return _clamp(mrad, -1571, 1571)

    # == the control tick (4) ======================================================================
    def tick(self, periods: int = 1) -> None:
        """One control tick. `periods` > 1 when the loop was stalled past whole periods: the
        missed ticks are skipped (the grid is kept) and the speed is measured over the span."""
        self.tick_count = (self.tick_count + 1) & 0xFFFF
        board = self.board
        config = self.config
        # 1. Sample (the board copies the counters atomically), 2. measure.
        now = board.micros()
        counts = self._read_counts()
        per_count = math.pi * config.wheel_diameter_um / 1000 / config.encoder_cpr / DT_S / periods
        for w in range(WHEEL_COUNT):
            delta = wrap_i32(counts[w] - self.counts[w])
            self.deltas[w] = delta
            self.measured[w] = round_half_away(delta * per_count)
        self.counts = counts
        # 3. Watchdog.
        if self.session.state is SessionState.ARMED and (now - self.last_valid_us) % _U32 >= self.watchdog_ms * 1000:
            self._fire(SessionEvent.WATCHDOG_EXPIRED, None, _Ctx(reason=FailsafeReason.COMM_TIMEOUT))
        # 4. Apply the latest setpoint.
        armed = self.session.state is SessionState.ARMED
        applied = False
        pending = self.pending
        self.pending = None
        if pending is not None and armed:
            self.targets[0], self.targets[1] = pending.targets
            if pending.servo_cdeg is not None:
                self.servo_cdeg = pending.servo_cdeg
            self.ack_seq = pending.seq
            self.ack_tick = self.tick_count
            applied = True
        # 5. Ramp, in exact integers of 0.01 mm/s (a limit in mm/s^2 times 10 ms is the limit
        # itself in those units), and 6. PID. Held at rest during the ESC's arming window, and out
        # of ARMED unless the safe state ramps down.
        esc_hold = self._esc_hold(now)
        self._esc_armed = not esc_hold
        hold = esc_hold or (not armed and config.safe_state is not SafeState.RAMP_DOWN)
        saturated = False
        moving = False
        for w in range(WHEEL_COUNT):
            pid = self.pids[w]
            if self._reset_integrator[w]:
                self._reset_integrator[w] = False
                pid.reset()
            if hold or w >= self.wheels:
                self.ramped_units[w] = 0
            else:
                self.ramped_units[w] = ramp_step(
                    self.ramped_units[w],
                    self.targets[w] * RAMP_UNITS,
                    config.accel_limit_mm_s2,
                    config.decel_limit_mm_s2,
                )
            target = 0 if esc_hold or w >= self.wheels else self.targets[w]
            u, sat = pid.update(
                target,
                self.ramped_units[w] / RAMP_UNITS,
                self.measured[w],
                gains=self.gains[w],
                max_effort=config.max_effort_permille,
                dt=DT_S,
            )
            self.efforts[w] = u
            saturated = saturated or sat
            moving = moving or not (target == 0 and self.ramped_units[w] == 0)
        self.saturated = saturated
        # 7. Output. Out of ARMED, RAMP_DOWN drives until every ramp is at 0, then coasts (in the
        # tick the last one gets there).
        self._write_outputs(driving=(armed or moving) and not esc_hold)
        # 8. Faults: effort applied but the encoder did not move.
        if self.caps & Capability.ENCODERS:
            for w in range(self.wheels):
                if abs(self.efforts[w]) >= ENCODER_FAULT_EFFORT and self.deltas[w] == 0:
                    self.stall_ticks[w] += 1
                else:
                    self.stall_ticks[w] = 0
                if self.stall_ticks[w] >= ENCODER_FAULT_TICKS and not self.encoder_fault[w]:
                    self.encoder_fault[w] = True
                    self._fire(SessionEvent.FAULT, None, _Ctx(reason=FailsafeReason.ENCODER_FAULT))
        # Lights, from the motion state; blinking phased on the ticks since boot.
        if self.caps & Capability.TURN_SIGNALS:
            steer = self.servo_cdeg - config.steering_center_cdeg
            ackermann = bool(self.caps & Capability.ACKERMANN)
            board.lights(
                light_mask(
                    self.session.state,
                    self.targets[0],
                    self.targets[1],
                    steer_cdeg=steer,
                    ackermann=ackermann,
                    blink=self._blink,
                )
            )
        self._blink = (self._blink + 1) % BLINK_PERIOD_TICKS
        # 9. Feedback.
        if self.session.open and self.feedback_mode is FeedbackMode.LOCKSTEP:
            if applied:
                self._send_feedback(now)
        else:
            self._fb_countdown -= 1
            if self._fb_countdown <= 0:
                self._fb_countdown = self._stream_period()
                self._send_feedback(now)

    def _read_counts(self) -> list[int]:
        raw = self.board.read_encoders()
        inv = self.config.encoder_invert
        return [wrap_i32(-raw[w] if inv >> w & 1 else raw[w]) for w in range(WHEEL_COUNT)]

    def _esc_hold(self, now: int) -> bool:
        """In the ESC's arming window (5): esc_arm_ms after boot, once. Latched over by the tick
        (`_esc_armed`): micros() wraps after 71.6 minutes, and the window must not come back then."""
        if not self.caps & Capability.ESC or self._esc_armed:
            return False
        return (now - self.boot_micros) % _U32 < self.config.esc_arm_ms * 1000

    def _stream_period(self) -> int:
        hz = self.feedback_hz if self.session.open else self.config.feedback_hz
        return max(1, round_half_away(CONTROL_RATE_HZ / max(1, hz)))

    def _write_outputs(self, driving: bool) -> None:
        """Step 7: drive from the efforts, or hold the configured safe state (5)."""
        c = self.config
        board = self.board
        if self.caps & Capability.ESC:
            u = self.efforts[0] if driving else 0
            if c.motor_invert & 1:
                u = -u
            if u >= 0:
                pulse = c.esc_neutral_us + round_half_away(u / 1000 * (c.esc_max_us - c.esc_neutral_us))
            else:
                pulse = c.esc_neutral_us + round_half_away(u / 1000 * (c.esc_neutral_us - c.esc_min_us))
            board.esc_pulse(pulse)
        else:
            hold = DriveMode.BRAKE if c.safe_state is SafeState.BRAKE else DriveMode.COAST
            for w in range(self.wheels):
                if driving:
                    u = -self.efforts[w] if c.motor_invert >> w & 1 else self.efforts[w]
                    board.drive(w, u, DriveMode.DRIVE)
                else:
                    board.drive(w, 0, hold)
        if self.caps & Capability.STEERING_SERVO:
            cdeg = self.servo_cdeg if self.session.state is SessionState.ARMED else c.steering_center_cdeg
            board.steering_pulse(c.servo_min_us + round_half_away(cdeg * (c.servo_max_us - c.servo_min_us) / 18000))

    def status(self) -> Status:
        state = self.session.state
        s = Status(0)
        if self.session.open:
            s |= Status.SESSION
            if self.feedback_mode is FeedbackMode.LOCKSTEP:
                s |= Status.LOCKSTEP
        if state is SessionState.ARMED:
            s |= Status.ARMED
        if state is SessionState.FAILSAFE:
            s |= Status.FAILSAFE
        if self.saturated:
            s |= Status.SATURATED
        if any(self.encoder_fault):
            s |= Status.ENCODER_FAULT
        if self.config_defaults:
            s |= Status.CONFIG_DEFAULTS
        return s

    def _send_feedback(self, now: int) -> None:
        self.sent_feedback += 1
        latched = self.latched if self.session.state is SessionState.FAILSAFE else FailsafeReason.NONE
        self._send(
            Feedback(
                boot_id=self.boot_id,
                mcu_time_us=now,
                tick=self.tick_count,
                ack_seq=self.ack_seq,
                ack_tick=self.ack_tick,
                status=self.status(),
                failsafe_reason=latched,
                encoder_counts=(self.counts[0], self.counts[1]),
                wheel_speed_mm_s=(_clamp(self.measured[0], -32768, 32767), _clamp(self.measured[1], -32768, 32767)),
                effort_permille=(self.efforts[0], self.efforts[1]),
                steering_mrad=self.steering_mrad() if self.session.state is SessionState.ARMED else 0,
            )
        )

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

    def _motors_safe(self) -> None:
        """Safe state (5): zero targets, setpoints and integrators; outputs to the configured state
        now (RAMP_DOWN keeps the ramps and lets the ticks bring them to zero first)."""
        self.pending = None
        self.targets = [0] * WHEEL_COUNT
        for pid in self.pids:
            pid.reset()
        self.stall_ticks = [0] * WHEEL_COUNT
        self.servo_cdeg = self.config.steering_center_cdeg
        if self.config.safe_state is not SafeState.RAMP_DOWN or not any(self.ramped_units):
            self.ramped_units = [0] * WHEEL_COUNT
            self.efforts = [0] * WHEEL_COUNT
            self._write_outputs(driving=False)
        elif self.caps & Capability.STEERING_SERVO:
            self._write_outputs(driving=True)  # still ramping down: the servo is centred at once

    def _accept_hello(self, ctx: _Ctx) -> None:
        msg = ctx.msg
        assert isinstance(msg, Hello)
        c = self.config
        self.watchdog_ms = _clamp(msg.watchdog_ms or c.watchdog_ms, WATCHDOG_MIN_MS, WATCHDOG_MAX_MS)
        # LOCKSTEP only where the build has the capability (the SDK reads the granted mode from
        # IDENTITY and refuses the session otherwise). NB: the C++ core grants it on every robot.
        wants_lockstep = msg.feedback_mode is FeedbackMode.LOCKSTEP
        lockstep_ok = bool(self.caps & Capability.LOCKSTEP)
        self.feedback_mode = FeedbackMode.LOCKSTEP if wants_lockstep and lockstep_ok else FeedbackMode.STREAM
        self.feedback_hz = _clamp(msg.feedback_hz or c.feedback_hz, 1, FEEDBACK_HZ_MAX)
        self._dup = None
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
        reply = Ack(req_id=msg.MSG_ID, req_seq=seq)
        self._send(reply)
        return reply

    def _nack(self, msg: Message | type[Message], seq: int, reason: NackReason, detail: int = 0) -> Nack:
        reply = Nack(req_id=msg.MSG_ID, req_seq=seq, reason=reason, detail=detail & 0xFF)
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
            link=self.link.counters(),
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
