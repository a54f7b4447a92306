"""The control side of the firmware model (docs/control.md 4, 5): its state and the control tick.

One tick: sample and measure the wheels, check the watchdog, take the latest setpoint, ramp and
run the PID, write the outputs (or hold the safe state), look for encoder faults, show the lights
and schedule FEEDBACK. `Firmware` (core.py) adds the link, the requests and the session.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from emulator.firmware.board import Board
from emulator.firmware.config import Gains
from emulator.firmware.control import WheelPid, limit_targets, ramp_step, round_half_away
from emulator.firmware.lights import BLINK_PERIOD_TICKS, lights_now
from emulator.firmware.session import Session
from emulator.firmware.statemachine import SessionEvent, SessionState
from protocol.codec.message import Message
from protocol.generated.constants import CONTROL_RATE_HZ, WHEEL_COUNT
from protocol.generated.enums import Capability, FailsafeReason, FeedbackMode, SafeState, Status
from protocol.generated.hardware import MotorMode
from protocol.generated.messages import Feedback, SetConfig, SetLights
from protocol.generated.profiles import RobotProfile

DT_S = 1.0 / CONTROL_RATE_HZ
TICK_US = 1_000_000 // CONTROL_RATE_HZ
ENCODER_FAULT_EFFORT = 300
ENCODER_FAULT_TICKS = 50
RAMP_UNITS = 100
"""Ramp resolution: units per mm/s."""
_U32 = 1 << 32


def wrap_i32(x: int) -> int:
    return (x + (1 << 31)) % _U32 - (1 << 31)


def clamp(x: int, lo: int, hi: int) -> int:
    return lo if x < lo else hi if x > hi else x


@dataclass(slots=True)
class Pending:
    """A setpoint accepted in ARMED and waiting for the tick that applies it."""

    seq: int
    targets: tuple[int, int]
    steering_mrad: int | None
    """The front-wheel angle (SET_ACKERMANN); None keeps the current one."""


class ControlTick:
    """The control state (what the C++ core keeps per wheel and for the outputs) and the tick."""

    # Kept by Firmware (core.py): the board, the configuration and the session's grants.
    board: Board
    config: SetConfig
    caps: Capability
    wheels: int
    session: Session
    gains: list[Gains]
    boot_id: int
    boot_micros: int
    watchdog_ms: int
    last_valid_us: int
    feedback_mode: FeedbackMode
    feedback_hz: int
    latched: FailsafeReason
    config_defaults: bool
    lights_setting: SetLights
    lit: int

    def _send(self, msg: Message) -> None:
        raise NotImplementedError

    def _failsafe(self, event: SessionEvent, reason: FailsafeReason) -> None:
        """Fire WATCHDOG_EXPIRED or FAULT with the reason to latch (Firmware runs the actions)."""
        raise NotImplementedError

    def _init_control(self, robot: RobotProfile) -> None:
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
        self.pending: list[Pending] = []
        """Waiting setpoints, the oldest first: stream mode at most one (latest wins), lockstep LOCKSTEP_QUEUE."""
        self.ack_seq = 0
        self.ack_tick = 0
        self.servo_cdeg = robot.config.steering_center_cdeg
        self.steer_mrad = 0
        """The latest setpoint's steering angle: the servo angle is re-limited from it every tick."""
        self.stall_ticks = [0] * WHEEL_COUNT
        self.encoder_fault = [False] * WHEEL_COUNT
        self._reset_integrator = [False] * WHEEL_COUNT
        self._fb_countdown = 1
        self._blink = 0
        self._esc_armed = False
        """The ESC's arming window is over (latched by the first tick after it)."""
        self.sent_feedback = 0

    # == the tick (4) ==============================================================================
    def tick(self, periods: int = 1) -> None:
        """One control tick. `periods` > 1 when the loop was stalled past whole periods: the
        missed ticks are skipped (the grid is kept) and the speed is measured over the span."""
        self.tick_count = (self.tick_count + 1) & 0xFFFF
        now = self.board.micros()
        self._measure(periods)  # 1. sample (the board copies the counters atomically), 2. measure
        if self.session.state is SessionState.ARMED and (now - self.last_valid_us) % _U32 >= self.watchdog_ms * 1000:
            self._failsafe(SessionEvent.WATCHDOG_EXPIRED, FailsafeReason.COMM_TIMEOUT)  # 3. watchdog
        armed = self.session.state is SessionState.ARMED
        applied = self._take_setpoint(armed)  # 4. the oldest waiting setpoint
        esc_hold = self._esc_hold(now)
        self._esc_armed = not esc_hold
        moving = self._ramp_and_pid(armed, esc_hold)  # 5. ramp, 6. PID
        # 7. Output. Out of ARMED, RAMP_DOWN drives until every ramp is at 0, then coasts (in the
        # tick the last one gets there).
        self._write_outputs(driving=(armed or moving) and not esc_hold)
        self._check_encoders()  # 8. faults
        self._show_lights()
        self._blink = (self._blink + 1) % BLINK_PERIOD_TICKS
        # 9. Feedback. Lockstep answers setpoints only while ARMED and streams out of it; the
        # countdown is held meanwhile, so the first tick out of ARMED streams one at once.
        if self.session.state is SessionState.ARMED and self.feedback_mode is FeedbackMode.LOCKSTEP:
            self._fb_countdown = 1
            if applied:
                self._send_feedback(now)
        else:
            self._fb_countdown -= 1
            if self._fb_countdown <= 0:
                self._fb_countdown = self._stream_period()
                self._send_feedback(now)

    def _measure(self, periods: int) -> None:
        config = self.config
        counts = self._read_counts()
        per_count = math.pi * config.wheel_diameter_um / 1000 / config.encoder_cpr / DT_S / periods
        for w in range(WHEEL_COUNT):
            delta = wrap_i32(counts[w] - self.counts[w])
            self.deltas[w] = delta
            # Without the ENCODERS capability there is nothing to measure (the C++ core reports 0).
            self.measured[w] = round_half_away(delta * per_count) if self.caps & Capability.ENCODERS else 0
        self.counts = counts

    def _take_setpoint(self, armed: bool) -> bool:
        """The oldest waiting setpoint becomes the targets (ARMED only); True when one was applied. Every
        tick re-limits the targets and the steering to the config in effect (4.4): a lowered limit
        applies at once, to the setpoint already running."""
        pending = self.pending.pop(0) if self.pending and armed else None
        if not armed:
            self.pending.clear()
        applied = pending is not None
        targets = list(self.targets)
        if pending is not None:
            targets = list(pending.targets)
            if pending.steering_mrad is not None:
                self.steer_mrad = pending.steering_mrad
            self.ack_seq = pending.seq
            self.ack_tick = self.tick_count
        self.targets = limit_targets(targets, self.config.max_wheel_speed_mm_s)
        self.servo_cdeg = self._servo_cdeg_for(self.steer_mrad)
        return applied

    def _ramp_and_pid(self, armed: bool, esc_hold: bool) -> bool:
        """Ramp, in exact integers of 0.01 mm/s (a limit in mm/s^2 times 10 ms is the limit itself
        in those units), and PID. Held at rest during the ESC's arming window, and out of ARMED
        unless the safe state ramps down. True while a wheel is still meant to move."""
        config = self.config
        hold = esc_hold or (not armed and config.safe_state is not SafeState.RAMP_DOWN)
        saturated = moving = False
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
            gains = self.gains[w]
            if not self.caps & Capability.ENCODERS:
                # Open loop (no encoder to close it on): the feed-forward alone.
                gains = Gains(0.0, 0.0, 0.0, gains.kf, gains.ks)
                pid.reset()
            u, sat = pid.update(
                target,
                self.ramped_units[w] / RAMP_UNITS,
                self.measured[w],
                gains=gains,
                max_effort=config.max_effort_permille,
                dt=DT_S,
            )
            self.efforts[w] = u
            saturated = saturated or sat
            moving = moving or not (target == 0 and self.ramped_units[w] == 0)
        self.saturated = saturated
        return moving

    def _check_encoders(self) -> None:
        """Effort applied but the encoder did not move, for ENCODER_FAULT_TICKS ticks: FAULT."""
        if not self.caps & Capability.ENCODERS:
            return
        for w in range(self.wheels):
            if abs(self.efforts[w]) >= ENCODER_FAULT_EFFORT and self.deltas[w] == 0:
                self.stall_ticks[w] += 1
            else:
                self.stall_ticks[w] = 0
            if self.stall_ticks[w] >= ENCODER_FAULT_TICKS and not self.encoder_fault[w]:
                self.encoder_fault[w] = True
                self._failsafe(SessionEvent.FAULT, FailsafeReason.ENCODER_FAULT)

    def _show_lights(self) -> None:
        """Lights, from the motion state or SET_LIGHTS; blinking phased on the ticks since boot."""
        if self.caps & Capability.TURN_SIGNALS:
            steer = self.servo_cdeg - self.config.steering_center_cdeg
            ackermann = bool(self.caps & Capability.ACKERMANN)
            self.lit = lights_now(
                self.session.state,
                self.lights_setting,
                self.targets[0],
                self.targets[1],
                steer_cdeg=steer,
                ackermann=ackermann,
                blink=self._blink,
            )
            self.board.lights(self.lit)

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
            hold = MotorMode.BRAKE if c.safe_state is SafeState.BRAKE else MotorMode.COAST
            for w in range(self.wheels):
                if driving:
                    u = -self.efforts[w] if c.motor_invert >> w & 1 else self.efforts[w]
                    board.drive(w, u, MotorMode.DRIVE)
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
                wheel_speed_mm_s=(clamp(self.measured[0], -32768, 32767), clamp(self.measured[1], -32768, 32767)),
                effort_permille=(self.efforts[0], self.efforts[1]),
                steering_mrad=self.steering_mrad() if self.session.state is SessionState.ARMED else 0,
            )
        )

    def _motors_safe(self) -> None:
        """Safe state (5): zero targets, setpoints and integrators; outputs to the configured state
        now (RAMP_DOWN keeps the ramps and lets the ticks bring them to zero first)."""
        self.pending.clear()
        self.targets = [0] * WHEEL_COUNT
        for pid in self.pids:
            pid.reset()
        self.stall_ticks = [0] * WHEEL_COUNT
        self.steer_mrad = 0
        self.servo_cdeg = self.config.steering_center_cdeg
        if self.config.safe_state is not SafeState.RAMP_DOWN or not any(self.ramped_units):
            self.ramped_units = [0] * WHEEL_COUNT
            self.efforts = [0] * WHEEL_COUNT
            self._write_outputs(driving=False)
        elif self.caps & Capability.STEERING_SERVO:
            self._write_outputs(driving=True)  # still ramping down: the servo is centred at once

    def _servo_cdeg_for(self, steering_mrad: int) -> int:
        c = self.config
        center = c.steering_center_cdeg
        cdeg = center + round_half_away(steering_mrad * 18000 / (1000 * math.pi))
        cdeg = clamp(cdeg, c.steering_min_cdeg, c.steering_max_cdeg)
        if c.steering_step_cdeg > 0:
            step = c.steering_step_cdeg
            cdeg = center + step * round_half_away((cdeg - center) / step)
            cdeg = clamp(cdeg, c.steering_min_cdeg, c.steering_max_cdeg)
        return cdeg

    def steering_mrad(self) -> int:
        if not self.caps & Capability.STEERING_SERVO:
            return 0
        mrad = round_half_away((self.servo_cdeg - self.config.steering_center_cdeg) * 1000 * math.pi / 18000)
        return clamp(mrad, Feedback.STEERING_MRAD_MIN, Feedback.STEERING_MRAD_MAX)
