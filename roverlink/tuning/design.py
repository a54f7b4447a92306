"""Choosing gains on the fitted model: the firmware's speed loop simulated, candidates compared.

SIMC alone (roverlink.tuning.fopdt.simc_gains) assumes a plain PI loop. The firmware adds a
feed-forward, and its integrator keeps integrating while the speed rises, so SIMC's gains
overshoot by 15-35 % on these wheels. The rule used here:

1. Start from SIMC (tau_c = theta_e): kp0 = tau / (K * 2 theta_e), Ti0 = min(tau, 8 theta_e), and
   the feed-forward (kf0, ks0): the line of efforts the wheel held (roverlink.tuning.feedforward),
   or without it the model's.
2. Simulate the firmware's loop on the model (100 Hz ticks; effort = kf*sp + ks + kp*e + integral,
   clamped to max_effort with conditional integration, as docs/control.md states it; speed
   measured over each tick) for kp in kp0 * {0.4 .. 1.5}, Ti in Ti0 * {1 .. 16},
   (kf, ks) in (kf0, ks0) * {0.8 .. 1.0}, and the gains in use (so the proposal is never worse than them on the model).
3. Rank the candidates by their 5 % settling time (to the tick) among those whose overshoot is
   at most 5 % (half the 10 % the tools promise, for the model's error); ties go to the smaller
   integral of absolute error.
4. On the robot (roverlink.tuning.tuner.Tuner.auto), step the best RANKED candidates and propose
   the one that measured fastest with under 10 % overshoot, if it settled at least as fast as the
   gains in use; otherwise keep those.

The model has no encoder quantisation nor the quantised speed's jitter: on the robot a gain set's
settling time varies by about a tick from one step to the next, so each is averaged over steps.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from host_sdk import PidGains
from roverlink.tuning.feedforward import StaticLine
from roverlink.tuning.fopdt import CONTROL_PERIOD_S, Fopdt, feed_forward, simc_gains
from roverlink.tuning.metrics import SETTLING_BAND, FloatArray

MAX_OVERSHOOT = 0.05
KP_FACTORS = (0.4, 0.55, 0.7, 0.85, 1.0, 1.2, 1.5)
TI_FACTORS = (1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 16.0)
KF_FACTORS = (0.8, 0.85, 0.9, 0.95, 1.0)
RANKED = 3
_SUBSTEPS = 10


@dataclass(frozen=True, slots=True)
class Design:
    gains: PidGains
    settling_s: float
    overshoot: float
    iae: float
    """Integral of |error| / step over the simulated hold, s."""
    simc: PidGains
    candidates: int
    ranked: tuple[PidGains, ...] = ()
    """The best candidates on the model, best first (the proposal is the first): what
    `Tuner.auto` tries on the robot."""
    line: StaticLine | None = None
    """The efforts held, the feed-forward's source (None: the model's)."""
    line_note: str = ""
    """Why the held efforts gave no line (then the model's feed-forward is used)."""


def simulate(
    model: Fopdt,
    gains: list[PidGains],
    step_mm_s: float,
    max_effort: float,
    *,
    hold_s: float = 0.6,
    line: StaticLine | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Measured speeds (mm/s, one row per gain set, one column per tick) for a step from rest. The
    model's steady speed is on `line` when given (the efforts held), else on the model's own."""
    n = len(gains)
    kp = np.array([g.kp for g in gains])
    ki = np.array([g.ki for g in gains])
    kf = np.array([g.kf for g in gains])
    ks = np.array([g.ks for g in gains]) * np.sign(step_mm_s)
    dt = CONTROL_PERIOD_S / _SUBSTEPS
    # The fit's dead time saw the speed as measured over a tick; half a tick of it is that.
    delay = max(0, round((model.theta_s - CONTROL_PERIOD_S / 2) / dt))
    # The effort at which the model's speed would be 0, and its steady speed per effort.
    offset, gain = (model.u2 - model.y2 / model.gain, model.gain) if line is None else (line.ks, 1 / line.kf)
    ticks = round(hold_s / CONTROL_PERIOD_S)
    y = np.zeros(n)
    integral = np.zeros(n)
    pipeline = [np.zeros(n) for _ in range(delay)]
    measured = np.zeros(n)
    out = np.zeros((n, ticks))
    decay = np.exp(-dt / model.tau_s)
    for k in range(ticks):
        e = step_mm_s - measured
        u_unsat = kf * step_mm_s + ks + kp * e + integral
        u = np.clip(u_unsat, -max_effort, max_effort)
        saturated = np.abs(u_unsat) > max_effort
        grow = ~saturated | ((u_unsat > max_effort) & (e < 0)) | ((u_unsat < -max_effort) & (e > 0))
        integral = np.where(grow, np.clip(integral + ki * e * CONTROL_PERIOD_S, -max_effort, max_effort), integral)
        acc = np.zeros(n)
        for _ in range(_SUBSTEPS):
            pipeline.append(u)
            applied = pipeline.pop(0)
            target = np.maximum(gain * (applied - offset), 0.0)
            y = target + (y - target) * decay
            acc += y
        measured = acc / _SUBSTEPS
        out[:, k] = measured
    return out, np.arange(1, ticks + 1, dtype=np.float64) * CONTROL_PERIOD_S


def _settled(speeds: FloatArray, t: FloatArray, step: float) -> tuple[FloatArray, FloatArray]:
    """Per row: the first tick from which the speed stays within the band, and the overshoot."""
    frac = speeds / step
    outside = np.abs(frac - 1.0) > SETTLING_BAND
    last = np.where(outside.any(axis=1), outside.shape[1] - np.argmax(outside[:, ::-1], axis=1), 0)
    settled = np.where(last >= len(t), np.inf, t[np.minimum(last, len(t) - 1)])
    return settled, np.maximum(frac.max(axis=1) - 1.0, 0.0)


def design_gains(
    model: Fopdt,
    step_mm_s: float,
    max_effort_permille: float,
    *,
    current: PidGains | None = None,
    line: StaticLine | None = None,
) -> Design:
    """The rule in the module docstring. `current`: the gains in use, also a candidate; `line`: the
    efforts the wheel held (roverlink.tuning.feedforward)."""
    simc = simc_gains(model)
    if line is not None:
        kf0, ks0 = line.kf, line.ks
    else:
        kf0, ks0 = feed_forward(model)
        if ks0 == 0.0:  # the line through the origin, at the step's speed
            kf0 = (model.u2 + (step_mm_s - model.y2) / model.gain) / step_mm_s
    ti0 = simc.kp / simc.ki
    grid = [
        PidGains(kp=simc.kp * a, ki=simc.kp * a / (ti0 * b), kd=0.0, kf=kf0 * c, ks=ks0 * c)
        for a, b, c in itertools.product(KP_FACTORS, TI_FACTORS, KF_FACTORS)
    ]
    if current is not None:
        grid.append(current)
    speeds, t = simulate(model, grid, step_mm_s, max_effort_permille, line=line)
    settling, overshoot = _settled(speeds, t, step_mm_s)
    iae = np.abs(speeds / step_mm_s - 1.0).sum(axis=1) * CONTROL_PERIOD_S
    allowed = np.nonzero(overshoot <= max(MAX_OVERSHOOT, float(overshoot.min())))[0]
    order = sorted((int(i) for i in allowed), key=lambda i: (settling[i], iae[i]))
    ranked = tuple(_typed_gains(grid[i]) for i in order if grid[i] is not current)[:RANKED]
    best = order[0]
    gains = current if grid[best] is current and current is not None else _typed_gains(grid[best])
    return Design(gains, float(settling[best]), float(overshoot[best]), float(iae[best]), simc, len(grid), ranked, line)


def _typed_gains(g: PidGains) -> PidGains:
    return PidGains(kp=_typed(g.kp), ki=_typed(g.ki), kd=0.0, kf=_typed(g.kf), ks=_typed(g.ks))


def _typed(x: float) -> float:
    """Four significant digits: what a person would type."""
    return float(f"{x:.4g}")
