"""The control law of docs/control.md 4: setpoint ramp and per-wheel PID (written once, here)."""

from __future__ import annotations

import math
from typing import TypeVar

from emulator.firmware.config import Gains

N = TypeVar("N", int, float)


def round_half_away(x: float) -> int:
    """Rounding used everywhere in docs/control.md: half away from zero."""
    return int(math.copysign(math.floor(abs(x) + 0.5), x))


def div_round(a: int, b: int) -> int:
    """Integer a / b (b > 0) rounded half away from zero, exactly as the C++ core's div_round."""
    return (a + b // 2) // b if a >= 0 else -((-a + b // 2) // b)


def limit_targets(targets: list[int], max_speed: int) -> list[int]:
    """Section 4.4: targets beyond +-max_speed are brought inside by one factor for both wheels
    (max_speed / peak, rounded half away from zero), so a turn keeps its curvature."""
    peak = max(abs(t) for t in targets)
    if peak <= max_speed:
        return targets
    return [div_round(t * max_speed, peak) for t in targets]


def ramp_step(ramped: N, target: N, accel_step: N, decel_step: N) -> N:
    """One tick of the ramp: toward `target` by at most `accel_step` when speeding up in the same
    direction (or from rest), else by at most `decel_step` (slowing, or reversing through zero).
    The firmware runs it on integers of 0.01 mm/s, so it is exact."""
    speeding_up = (ramped == 0 or (ramped > 0) == (target > 0)) and abs(target) > abs(ramped)
    limit = accel_step if speeding_up else decel_step
    diff = target - ramped
    if diff > limit:
        return ramped + limit
    if diff < -limit:
        return ramped - limit
    return target


class WheelPid:
    """Velocity PID with feed-forward (setpoint and static friction), derivative on measurement and
    conditional integration."""

    __slots__ = ("integral", "m_prev", "u", "u_unsat")

    def __init__(self) -> None:
        self.integral = 0.0
        self.m_prev = 0
        self.u = 0
        self.u_unsat = 0.0

    def reset(self) -> None:
        self.integral = 0.0

    def update(
        self, target: float, ramped: float, measured: int, *, gains: Gains, max_effort: int, dt: float
    ) -> tuple[int, bool]:
        """This tick's effort (integer permille) and whether it saturated."""
        m_prev, self.m_prev = self.m_prev, measured
        if target == 0 and ramped == 0:
            # No hum at standstill: zero output, zero integrator.
            self.integral = 0.0
            self.u = 0
            self.u_unsat = 0.0
            return 0, False
        limit = float(max_effort)
        # A lowered max_effort bounds the integrator from this tick on, integrating or not.
        self.integral = max(-limit, min(limit, self.integral))
        e = ramped - measured
        p = gains.kp * e
        d = -gains.kd * (measured - m_prev) / dt
        # Static friction fed forward with the setpoint's sign: a wheel starting from rest or
        # reversing gets its breakaway effort at once, not after the integrator has learnt it.
        s = gains.ks if ramped > 0 else (-gains.ks if ramped < 0 else 0.0)
        u_unsat = gains.kf * ramped + s + p + self.integral + d
        saturated = abs(u_unsat) > limit
        u = round_half_away(max(-limit, min(limit, u_unsat)))
        # Conditional integration: integrate when unsaturated, or when the error pulls back in.
        if not saturated or (u_unsat > limit and e < 0) or (u_unsat < -limit and e > 0):
            self.integral = max(-limit, min(limit, self.integral + gains.ki * e * dt))
        self.u = u
        self.u_unsat = u_unsat
        return u, saturated
