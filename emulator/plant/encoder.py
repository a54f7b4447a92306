"""Quadrature encoder on a wheel (or on the motor, counted per wheel turn after gearing).

The decoded count is floor(revolutions * cpr + phase) - floor(phase), with revolutions signed in
the encoder's own direction (a mirrored encoder counts down when the wheel rolls forward). A
disconnected encoder (a signal wire off) stops producing edges: its count freezes while the wheel
keeps turning.
"""

from __future__ import annotations

import math


class QuadratureEncoder:
    __slots__ = ("_base", "connected", "count", "cpr", "phase", "polarity")

    def __init__(self, cpr: int, polarity: int, phase: float = 0.0) -> None:
        self.cpr = cpr
        self.polarity = polarity
        self.phase = phase
        self.connected = True
        self.count = 0
        """Edges counted since power-up (what an MCU counting every edge would hold)."""
        self._base = math.floor(phase)

    def position(self, wheel_angle_rad: float) -> int:
        """Edges between the power-up position and `wheel_angle_rad` (robot-forward positive)."""
        revs = self.polarity * wheel_angle_rad / (2 * math.pi)
        return math.floor(revs * self.cpr + self.phase) - self._base

    def update(self, wheel_angle_rad: float) -> None:
        if self.connected:
            self.count = self.position(wheel_angle_rad)

    def reconnect(self, wheel_angle_rad: float) -> None:
        """Edges resume from where the wheel is now; those missed while disconnected are lost."""
        if not self.connected:
            self._base += self.position(wheel_angle_rad) - self.count
            self.connected = True
