"""The feed-forward (kf, ks) from what the closed loop holds at two speeds.

A wheel's steady effort is close to a line in its speed: effort = kf * speed + ks, where ks is
the effort that keeps the wheel turning at the lowest speeds (friction, the gearbox, the driver's
deadband; a little under what starts it). With the line fed forward (ks with the setpoint's sign,
docs/control.md), the integrator only corrects load and the small rest of the breakaway, so a
wheel starting from rest or reversing does not wait for it to learn the friction
(benchmarks/veer.py).

The line is measured, not inferred from the open-loop model: the wheel holds a low speed and then
the test speed under a PI loop of the tuning's own (SIMC's gains on the model, so that gains in use
without an integrator still give a line), and the mean effort over the last part of each hold is
what the feed-forward must supply there. Holds that missed their speeds give no line: the model's
is used then. The open-loop step (roverlink.tuning.fopdt) gives the
dynamics; its two operating points sit where the motor's curve bends, so a line through them
misses the slope at speed by about 10 %.
"""

from __future__ import annotations

from dataclasses import dataclass

from roverlink.tuning.fopdt import IdentificationError
from roverlink.tuning.metrics import StepResponse

HELD_LOW = 0.1
"""The low hold, as a fraction of the test speed: just above breakaway."""
HELD_LOW_S = 1.0
"""How long the low speed is held before the step (the integrator settles on the friction)."""
HELD_HIGH_S = 1.0
"""How long the test speed is held (at least; longer with a longer --hold)."""
_SETTLED_S = 0.4
"""Each hold's last part, averaged (at most 40 % of the hold)."""
_HELD_TOL = 0.15
_HELD_TOL_MM_S = 3.0
"""A hold counts when its mean speed is within 15 % + 3 mm/s of its setpoint."""


class LineError(IdentificationError):
    """The two holds do not give a line (the wheel did not hold the speeds)."""


@dataclass(frozen=True, slots=True)
class StaticLine:
    """effort = kf * speed + ks, permille and mm/s (the firmware's units)."""

    kf: float
    ks: float
    speeds_mm_s: tuple[float, float]
    efforts: tuple[float, float]
    """Permille, at the two speeds."""

    def describe(self) -> str:
        (v1, v2), (u1, u2) = self.speeds_mm_s, self.efforts
        return (
            f"steady effort {u1:.0f} permille at {v1:.0f} mm/s, {u2:.0f} at {v2:.0f}: "
            f"kf {self.kf:.3f} per mm/s, ks {self.ks:.0f} permille"
        )


def held_line(response: StepResponse) -> StaticLine:
    """The line through the efforts `response` held before its step and at the end of its hold."""
    t = response.t_s
    low = (t < 0) & (t >= -_SETTLED_S)
    window = min(_SETTLED_S, 0.4 * response.hold_s)
    high = (t < response.hold_s) & (t >= response.hold_s - window)
    if low.sum() < 5 or high.sum() < 5:
        raise LineError(f"the holds gave {int(low.sum())} and {int(high.sum())} samples: lengthen the test")
    v1, v2 = (float(response.speed_m_s[m].mean()) * 1000 for m in (low, high))
    u1, u2 = (float(response.effort[m].mean()) * 1000 for m in (low, high))
    s1, s2 = (float(response.setpoint_m_s[m].mean()) * 1000 for m in (low, high))
    for held, wanted in ((v1, s1), (v2, s2)):
        if abs(held - wanted) > _HELD_TOL * abs(wanted) + _HELD_TOL_MM_S:
            raise LineError(
                f"the wheel held {held:.0f} mm/s for a setpoint of {wanted:.0f} mm/s: the holds did not settle"
            )
    if v2 - v1 < 20.0 or u2 <= u1:  # the setpoints themselves were too close
        raise LineError(
            f"the wheel held {v1:.0f} and {v2:.0f} mm/s at {u1:.0f} and {u2:.0f} permille: "
            "no line (is the wheel free to spin, and does it follow the motor?)"
        )
    kf = (u2 - u1) / (v2 - v1)
    ks = max(0.0, u1 - kf * v1)
    if ks == 0.0:
        kf = u2 / v2  # no friction to speak of: the line through the origin at the test speed
    return StaticLine(kf, ks, (v1, v2), (u1, u2))
