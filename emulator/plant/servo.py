"""Hobby steering servo and linkage.

Pulse -> commanded angle:  angle = (pulse - min_us) / (max_us - min_us) * 180 deg, clamped to the
mechanical travel [travel_min_deg, travel_max_deg], then quantised to the servo's resolution
(its deadband: it does not move for smaller changes). The horn moves toward the commanded angle at
no more than `slew_deg_s`. The front wheels' angle is (horn - straight_deg) * linkage_ratio, positive
to the left. Without pulses the servo holds its position.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class ServoParams:
    min_us: int = 500
    """Pulse width at 0 degrees."""
    max_us: int = 2500
    """Pulse width at 180 degrees."""
    travel_min_deg: float = 0.0
    travel_max_deg: float = 180.0
    resolution_deg: float = 0.5
    """Smallest step the servo resolves (quantisation of the commanded angle)."""
    slew_deg_s: float = 400.0
    """Top speed of the horn (a typical 0.15 s / 60 deg servo)."""
    straight_deg: float = 90.0
    """Horn angle at which the wheels point straight (the real centre; the config holds a guess)."""
    linkage_ratio: float = 1.0
    """Front-wheel angle per horn angle."""


class SteeringServo:
    __slots__ = ("angle_deg", "params", "pulse_us", "target_deg")

    def __init__(self, params: ServoParams) -> None:
        self.params = params
        self.angle_deg = params.straight_deg
        self.target_deg = params.straight_deg
        self.pulse_us = 0

    def set_pulse(self, pulse_us: int) -> None:
        self.pulse_us = pulse_us
        if pulse_us <= 0:
            return  # no pulses: hold
        p = self.params
        angle = (pulse_us - p.min_us) * 180.0 / (p.max_us - p.min_us)
        angle = max(p.travel_min_deg, min(p.travel_max_deg, angle))
        if p.resolution_deg > 0:
            angle = round(angle / p.resolution_deg) * p.resolution_deg
        self.target_deg = angle

    def step(self, dt_s: float) -> None:
        room = self.params.slew_deg_s * dt_s
        diff = self.target_deg - self.angle_deg
        self.angle_deg += max(-room, min(room, diff))

    @property
    def wheel_angle_rad(self) -> float:
        p = self.params
        return math.radians((self.angle_deg - p.straight_deg) * p.linkage_ratio)
