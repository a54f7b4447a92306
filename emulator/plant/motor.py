"""Brushed DC motor with gearbox behind an H-bridge (TB6612, L298N, BTS7960).

Electrical:  L di/dt = V - R i - ke * G * w          (w: wheel speed, rad/s; G: gear ratio)
Torque:      tau_wheel = eta * G * kt * i             (kt = ke in SI units)
Voltage:     V = supply_v * d_eff, d_eff = sign(d) * (|d| - deadband) / (1 - deadband) above the
             driver's deadband and 0 below it (short PWM pulses do not switch the bridge).

Friction (Coulomb and viscous, at the wheel) is applied by the vehicle solver, which knows the
inertia it acts on. The current is advanced with the exact solution of the linear ODE for a step
with constant V and w, so the winding time constant L/R can be far shorter than the step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from protocol.generated.hardware import MotorMode


@dataclass(frozen=True, slots=True)
class MotorParams:
    supply_v: float
    """Battery voltage at the bridge at full duty."""
    resistance_ohm: float
    """Winding (plus bridge) resistance."""
    inductance_h: float
    """Winding inductance: electrical time constant L/R."""
    ke_v_s_rad: float
    """Back-EMF constant at the motor shaft (equal to the torque constant in N m/A)."""
    gear_ratio: float
    """Motor turns per wheel turn."""
    efficiency: float
    """Gearbox efficiency (0..1)."""
    rotor_inertia_kg_m2: float
    """Rotor inertia at the motor shaft (reflected to the wheel as J * G^2)."""
    coulomb_nm: float
    """Dry friction of motor and gearbox, at the wheel."""
    viscous_nm_s_rad: float
    """Viscous friction at the wheel."""
    deadband: float
    """Duty fraction below which the bridge produces no voltage."""
    current_limit_a: float = math.inf
    """Driver current limit (ESCs and some bridges limit current)."""

    @property
    def electrical_time_constant_s(self) -> float:
        return self.inductance_h / self.resistance_ohm

    @property
    def torque_per_volt(self) -> float:
        """Stall torque at the wheel per volt applied, N m / V."""
        return self.efficiency * self.gear_ratio * self.ke_v_s_rad / self.resistance_ohm

    @property
    def emf_damping(self) -> float:
        """Back-EMF damping at the wheel, N m s / rad: torque lost per rad/s of wheel speed."""
        return self.efficiency * self.gear_ratio**2 * self.ke_v_s_rad**2 / self.resistance_ohm

    @property
    def reflected_inertia(self) -> float:
        return self.rotor_inertia_kg_m2 * self.gear_ratio**2


class DcMotor:
    """One motor and its bridge channel. `polarity` -1 models a motor mounted mirrored."""

    __slots__ = ("_decay", "_dt", "current_a", "duty", "mode", "params", "polarity", "voltage_v")

    def __init__(self, params: MotorParams, polarity: int, dt_s: float) -> None:
        self.params = params
        self.polarity = polarity
        self.duty = 0.0
        self.mode = MotorMode.COAST
        self.current_a = 0.0
        self.voltage_v = 0.0
        self._dt = dt_s
        self._decay = math.exp(-dt_s / params.electrical_time_constant_s)

    def command(self, duty: float, mode: MotorMode) -> None:
        """Bridge input: signed duty -1..1 (used in DRIVE) and mode."""
        self.duty = max(-1.0, min(1.0, duty)) if mode is MotorMode.DRIVE else 0.0
        self.mode = mode

    def effective_duty(self) -> float:
        d = self.duty
        db = self.params.deadband
        if abs(d) <= db:
            return 0.0
        return math.copysign((abs(d) - db) / (1.0 - db), d)

    def step(self, wheel_rad_s: float) -> float:
        """Advance the winding current by one step at wheel speed `wheel_rad_s` (robot-forward
        positive); returns the motor torque at the wheel (robot-forward positive)."""
        p = self.params
        if self.mode is MotorMode.COAST:
            # Bridge off: the flyback diodes clamp the winding and the current dies within
            # microseconds, far below the step, so it is simply zero.
            self.current_a = 0.0
            self.voltage_v = 0.0
            return 0.0
        volts = p.supply_v * self.effective_duty() if self.mode is MotorMode.DRIVE else 0.0
        self.voltage_v = volts
        # Motor-frame quantities: a mirrored motor turns the other way for the same wheel motion.
        shaft = self.polarity * wheel_rad_s * p.gear_ratio
        i_ss = (volts - p.ke_v_s_rad * shaft) / p.resistance_ohm
        i = i_ss + (self.current_a - i_ss) * self._decay
        limit = p.current_limit_a
        if i > limit:
            i = limit
        elif i < -limit:
            i = -limit
        self.current_a = i
        return self.polarity * p.efficiency * p.gear_ratio * p.ke_v_s_rad * i
