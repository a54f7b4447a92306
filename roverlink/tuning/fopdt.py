"""A first-order-plus-dead-time model of one wheel, fitted to an open-loop effort step, and the
tuning rule that turns it into PID gains.

Identification: with the PID reduced to its feed-forward (kp = ki = kd = 0), a speed setpoint is
an effort command, effort = kf * setpoint: open loop. The wheel first runs at a lower effort u1
(so gearbox friction and the driver's deadband are behind it), then the effort steps to u2. The
speed's answer is fitted by least squares with

    y(t) = y1 + K (u2 - u1) (1 - exp(-(t - theta) / tau))   for t >= theta, y1 before,

K in (mm/s) per permille, tau the time constant, theta the dead time as the firmware's PID sees
it (the speed is measured over the previous tick, so half a tick of it is the measurement).

The starting point of the tuning rule (roverlink.tuning.design refines it on the model): SIMC
(Skogestad, "Simple analytic rules for model reduction and PID controller tuning", J. Process
Control 13, 2003) for a PI controller, with the "tight control" closed-loop
time constant tau_c = theta_e and the sample-and-hold of the 100 Hz loop counted as half a
period of extra dead time (theta_e = theta + T/2):

    kp = tau / (K (tau_c + theta_e)),  Ti = min(tau, 4 (tau_c + theta_e)),  ki = kp / Ti,  kd = 0,

plus the feed-forward of the two steady states: the line effort = kf * speed + ks through
(y1, u1) and (y2, u2), so kf = 1 / K and ks = u2 - y2 / K, the effort at which the line leaves
zero speed (static friction, fed forward with the setpoint's sign). A line that would need a
negative ks is replaced by kf = u2 / y2 through the origin. The integrator then only corrects
what load adds or takes away, and a wheel starting from rest or reversing does not wait for it
to learn the friction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from host_sdk import PidGains
from protocol.generated.constants import CONTROL_RATE_HZ
from roverlink.tuning.metrics import FloatArray

CONTROL_PERIOD_S = 1.0 / CONTROL_RATE_HZ
_THETA_MAX_S = 0.2
_TAU_RANGE_S = (0.004, 3.0)


class IdentificationError(ValueError):
    """The open-loop step did not give a usable model (the wheel did not move, or no settling)."""


@dataclass(frozen=True, slots=True)
class Fopdt:
    gain: float
    """K: steady speed change per effort change, (mm/s) per permille."""
    tau_s: float
    theta_s: float
    u1: float
    u2: float
    """The two efforts (permille)."""
    y1: float
    y2: float
    """The steady speeds they gave (mm/s)."""
    rms_error: float
    """Fit residual, mm/s."""

    def response(self, t: FloatArray) -> FloatArray:
        """The model's speed (mm/s) at times t (s) after the effort step."""
        rise = 1.0 - np.exp(-np.maximum(t - self.theta_s, 0.0) / self.tau_s)
        out: FloatArray = self.y1 + self.gain * (self.u2 - self.u1) * rise
        return out

    def describe(self) -> str:
        return (
            f"K {self.gain:.3f} mm/s per permille, tau {self.tau_s * 1000:.1f} ms, "
            f"dead time {self.theta_s * 1000:.1f} ms (fit rms {self.rms_error:.1f} mm/s)"
        )


def fit_fopdt(t: FloatArray, speed_mm_s: FloatArray, u1: float, u2: float) -> Fopdt:
    """Fit the model to speeds after an effort step at t = 0 from u1 to u2 (samples before 0:
    the steady speed at u1). Grid search over theta, least squares over tau at each."""
    before = speed_mm_s[t < 0]
    after_mask = t >= 0
    ta, ya = t[after_mask], speed_mm_s[after_mask]
    if len(before) < 3 or len(ta) < 20:
        raise IdentificationError("too few samples around the step: lengthen the test")
    y1 = float(before[-min(len(before), 20) :].mean())
    tail = ta >= ta[-1] * 0.7
    y2 = float(ya[tail].mean())
    du = u2 - u1
    dy = y2 - y1
    if du == 0 or abs(dy) < 5.0 or dy / du <= 0:
        raise IdentificationError(
            f"the wheel's speed went {y1:.0f} -> {y2:.0f} mm/s for an effort step {u1:.0f} -> {u2:.0f} permille: "
            "it does not follow the motor (check calibration: motor and encoder direction)"
        )
    best = (math.inf, 0.0, 0.0)
    taus = np.geomspace(*_TAU_RANGE_S, 160)
    thetas = np.arange(0.0, _THETA_MAX_S, 0.001)
    norm = (ya - y1) / dy
    for theta in thetas:
        lag = np.maximum(ta - theta, 0.0)[None, :]
        model = 1.0 - np.exp(-lag / taus[:, None])
        sse = ((model - norm[None, :]) ** 2).sum(axis=1)
        i = int(sse.argmin())
        if sse[i] < best[0]:
            best = (float(sse[i]), float(taus[i]), float(theta))
    sse, tau, theta = best
    rms = math.sqrt(sse / len(ta)) * abs(dy)
    return Fopdt(dy / du, tau, theta, u1, u2, y1, y2, rms)


def simc_gains(model: Fopdt) -> PidGains:
    """PI gains by the SIMC rule (module docstring) plus the feed-forward; firmware units."""
    theta_e = model.theta_s + CONTROL_PERIOD_S / 2
    tau_c = theta_e
    kp = model.tau_s / (model.gain * (tau_c + theta_e))
    ti = min(model.tau_s, 4 * (tau_c + theta_e))
    kf, ks = feed_forward(model)
    return PidGains(kp=_f32_round(kp), ki=_f32_round(kp / ti), kd=0.0, kf=_f32_round(kf), ks=_f32_round(ks))


def feed_forward(model: Fopdt) -> tuple[float, float]:
    """(kf, ks): the steady-state line through the model's two operating points (module docstring)."""
    ks = model.u2 - model.y2 / model.gain
    if ks > 0:
        return 1.0 / model.gain, ks
    return (model.u2 / model.y2 if model.y2 else 0.0), 0.0


def _f32_round(x: float) -> float:
    """Four significant digits: what a person would type, and what the board stores exactly enough."""
    return float(f"{x:.4g}")
