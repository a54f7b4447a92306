"""RC electronic speed controller driving a sensorless brushless motor.

The ESC reads servo pulses (normally 1000..2000 us at 50 Hz). At power-up, and again after the
signal has been lost, it will not drive until it has seen a steady neutral pulse for
`calibration_ms`; it learns that pulse as its neutral point (the firmware's boot calibration
window, esc_arm_ms, exists to give it that). Pulses inside `neutral_band_us` of the learned neutral
mean stop (coast, or a drag brake). Outside the band the throttle is linear up to the end points.
A pulse that is not near neutral during calibration restarts it: a real ESC refuses to arm with the
throttle open.

The brushless motor behind it is modelled as a DC motor with the ESC's output as its duty cycle
(`throttle`), which is how a sensorless ESC behaves above its start-up speed.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass


class EscState(enum.IntEnum):
    NO_SIGNAL = 0
    """Unpowered, or no pulses: output off; waits for pulses."""
    CALIBRATING = 1
    """Seeing pulses; waiting for `calibration_ms` of steady neutral."""
    READY = 2
    """Armed: drives the motor from the pulse width."""


@dataclass(frozen=True, slots=True)
class EscParams:
    min_us: int = 1000
    """Pulse for full reverse."""
    max_us: int = 2000
    """Pulse for full forward."""
    nominal_neutral_us: int = 1500
    """Neutral the ESC expects; calibration accepts pulses within `calibration_tolerance_us`."""
    calibration_tolerance_us: int = 100
    neutral_band_us: int = 30
    """Half-width of the stop band around the learned neutral."""
    calibration_ms: int = 2000
    """Steady neutral needed before the ESC arms."""
    signal_timeout_ms: int = 100
    """No pulse for this long: output off, calibration needed again."""
    drag_brake: float = 0.0
    """0: coast at neutral; 1: full brake."""


class Esc:
    __slots__ = (
        "_cal_n",
        "_cal_start_us",
        "_cal_sum",
        "_last_pulse_us",
        "learned_neutral_us",
        "params",
        "pulse_us",
        "state",
        "throttle",
    )

    def __init__(self, params: EscParams) -> None:
        self.params = params
        self.state = EscState.NO_SIGNAL
        self.pulse_us = 0
        self.throttle = 0.0
        self.learned_neutral_us = params.nominal_neutral_us
        self._last_pulse_us = -(10**12)
        self._cal_start_us = 0
        self._cal_sum = 0
        self._cal_n = 0

    def power_cycle(self) -> None:
        """Supply lost (brown-out): everything learned is forgotten."""
        self.state = EscState.NO_SIGNAL
        self.pulse_us = 0
        self.throttle = 0.0

    def set_pulse(self, pulse_us: int) -> None:
        """Pulse width the MCU sends from now on (0 = no pulses)."""
        self.pulse_us = pulse_us

    def step(self, now_us: int) -> float:
        """Advance to `now_us`; returns the throttle -1..1 (0 also when not driving)."""
        p = self.params
        pulse = self.pulse_us
        if pulse > 0:
            self._last_pulse_us = now_us
        elif now_us - self._last_pulse_us > p.signal_timeout_ms * 1000:
            self.state = EscState.NO_SIGNAL
        if self.state is EscState.NO_SIGNAL:
            self.throttle = 0.0
            if pulse > 0:
                self.state = EscState.CALIBRATING
                self._restart_calibration(now_us)
            else:
                return 0.0
        if self.state is EscState.CALIBRATING:
            self.throttle = 0.0
            if pulse <= 0:
                return 0.0
            if abs(pulse - p.nominal_neutral_us) > p.calibration_tolerance_us:
                self._restart_calibration(now_us)
                return 0.0
            self._cal_sum += pulse
            self._cal_n += 1
            if now_us - self._cal_start_us >= p.calibration_ms * 1000:
                self.learned_neutral_us = round(self._cal_sum / self._cal_n)
                self.state = EscState.READY
            return 0.0
        if pulse <= 0:  # pulses missing, but not yet for signal_timeout: hold the last throttle
            return self.throttle
        neutral = self.learned_neutral_us
        band = p.neutral_band_us
        if pulse > neutral + band:
            t = (pulse - neutral - band) / max(1, p.max_us - neutral - band)
        elif pulse < neutral - band:
            t = -(neutral - band - pulse) / max(1, neutral - band - p.min_us)
        else:
            t = 0.0
        self.throttle = max(-1.0, min(1.0, t))
        return self.throttle

    def _restart_calibration(self, now_us: int) -> None:
        self._cal_start_us = now_us
        self._cal_sum = 0
        self._cal_n = 0
