"""Step responses and their metrics: rise time, overshoot, settling time, steady-state error, saturation.

The firmware measures a wheel's speed from the encoder counts of one control tick, so a single
sample is quantised to one count per tick (13 mm/s on the diff-drive car, 28 mm/s on the PiCar).
The metrics therefore read a centred moving average over `SMOOTH_SAMPLES` samples (the same as
speed over 50 ms of counts); the plots show both.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from host_sdk import PidGains

SMOOTH_SAMPLES = 5
SETTLING_BAND = 0.05
"""Settled: within 5 % of the step, for good."""
STEADY_FRACTION = 0.3
"""The steady-state error is the mean error over the last 30 % of the hold."""

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class StepResponse:
    """One wheel's response to a velocity step, on the MCU's clock (t = 0: the tick that applied it)."""

    wheel: int
    gains: PidGains
    label: str
    """What was tested, e.g. "current" or "auto (SIMC)"."""
    step_m_s: float
    """The step's size (setpoint after minus before)."""
    hold_s: float
    """How long the step setpoint was held."""
    t_s: FloatArray
    setpoint_m_s: FloatArray
    speed_m_s: FloatArray
    effort: FloatArray
    """-1..1."""
    saturated: NDArray[np.bool_]

    @property
    def smoothed_m_s(self) -> FloatArray:
        return smooth(self.speed_m_s)

    def during_hold(self) -> NDArray[np.bool_]:
        mask: NDArray[np.bool_] = (self.t_s >= 0) & (self.t_s < self.hold_s)
        return mask


@dataclass(frozen=True, slots=True)
class StepMetrics:
    rise_time_s: float | None
    """10 % to 90 % of the step (None: never got there)."""
    overshoot: float
    """Peak beyond the setpoint as a fraction of the step (0: none)."""
    settling_time_s: float | None
    """From the step until the speed stays within SETTLING_BAND of the setpoint (None: never)."""
    steady_state_error: float
    """Mean error over the end of the hold, as a fraction of the step (positive: too fast)."""
    saturation: float
    """Fraction of the hold the firmware reported its effort saturated."""
    peak_effort: float

    def row(self) -> str:
        def ms(v: float | None) -> str:
            return f"{v * 1000:6.0f} ms" if v is not None else "   never"

        return (
            f"rise {ms(self.rise_time_s)}  overshoot {self.overshoot * 100:5.1f} %  settling {ms(self.settling_time_s)}"
            f"  ss error {self.steady_state_error * 100:+5.1f} %  saturated {self.saturation * 100:4.0f} %"
        )


def smooth(x: FloatArray, n: int = SMOOTH_SAMPLES) -> FloatArray:
    """Centred moving average; the ends use the samples there are."""
    if len(x) == 0:
        return x
    kernel = np.ones(n)
    total = np.convolve(x, kernel, mode="same")
    count = np.convolve(np.ones(len(x)), kernel, mode="same")
    out: FloatArray = total / count
    return out


def step_metrics(r: StepResponse) -> StepMetrics:
    hold = r.during_hold()
    t = r.t_s[hold]
    y = smooth(r.speed_m_s[hold])  # within the hold: the window never reaches past its ends
    base = float(r.setpoint_m_s[hold][0] - r.step_m_s) if hold.any() else 0.0
    step = r.step_m_s
    if len(t) == 0 or step == 0:
        return StepMetrics(None, 0.0, None, math.nan, 0.0, 0.0)
    frac = (y - base) / step
    rise = _crossing(t, frac, 0.9)
    start = _crossing(t, frac, 0.1)
    rise_time = rise - start if rise is not None and start is not None else None
    overshoot = max(0.0, float(frac.max()) - 1.0)
    settling = _settling(t, frac)
    tail = t >= t[0] + (1 - STEADY_FRACTION) * (t[-1] - t[0])
    raw = (r.speed_m_s[hold] - base) / step
    sse = float(raw[tail].mean() - 1.0)
    return StepMetrics(
        rise_time_s=rise_time,
        overshoot=overshoot,
        settling_time_s=settling,
        steady_state_error=sse,
        saturation=float(r.saturated[hold].mean()),
        peak_effort=float(np.abs(r.effort[hold]).max()),
    )


def _settling(t: FloatArray, frac: FloatArray) -> float | None:
    """When `frac` enters the band around 1 for good: interpolated between the last sample
    outside and the first inside, so two responses compare below the sample period."""
    error = np.abs(frac - 1.0)
    outside = np.nonzero(error > SETTLING_BAND)[0]
    if len(outside) == 0:
        return float(t[0])
    i = int(outside[-1])
    if i == len(t) - 1:
        return None
    e0, e1 = error[i], error[i + 1]
    return float(t[i] + (e0 - SETTLING_BAND) / (e0 - e1) * (t[i + 1] - t[i]))


def _crossing(t: FloatArray, frac: FloatArray, level: float) -> float | None:
    """First time `frac` reaches `level`, interpolated between samples."""
    above = np.nonzero(frac >= level)[0]
    if len(above) == 0:
        return None
    i = int(above[0])
    if i == 0:
        return float(t[0])
    f0, f1 = frac[i - 1], frac[i]
    return float(t[i - 1] + (level - f0) / (f1 - f0) * (t[i] - t[i - 1]))


def mean_metrics(runs: list[StepMetrics]) -> StepMetrics:
    """Several steps of one gain set: mean times and errors, worst overshoot and peak effort
    (a settling or rise time that never came makes the mean None)."""

    def mean(values: list[float | None]) -> float | None:
        return None if any(v is None for v in values) else sum(v for v in values if v is not None) / len(values)

    return StepMetrics(
        rise_time_s=mean([m.rise_time_s for m in runs]),
        overshoot=max(m.overshoot for m in runs),
        settling_time_s=mean([m.settling_time_s for m in runs]),
        steady_state_error=sum(m.steady_state_error for m in runs) / len(runs),
        saturation=sum(m.saturation for m in runs) / len(runs),
        peak_effort=max(m.peak_effort for m in runs),
    )
