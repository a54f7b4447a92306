"""The tune plot: each wheel's step responses (current gains and candidates) and their efforts.

matplotlib with the Agg backend (no display needed), imported when a plot is drawn (`plot` extra).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from host_sdk.extras import require
from roverlink.tuning.metrics import StepMetrics, StepResponse, smooth


def plot_steps(
    rows: Sequence[Sequence[tuple[StepResponse, StepMetrics]]], path: str | Path, title: str = "", dpi: int = 80
) -> Path:
    """One row per wheel: speed (setpoint dashed, each trial smoothed, raw samples faint) and effort."""
    mpl = require("matplotlib", "plot", "the tune plot")
    mpl.use("Agg")
    plt = require("matplotlib.pyplot", "plot", "the tune plot")
    fig, axes = plt.subplots(len(rows), 2, figsize=(10, 3.2 * len(rows)), squeeze=False, sharex=True)
    for r, trials in enumerate(rows):
        ax_v, ax_u = axes[r]
        for i, (resp, m) in enumerate(trials):
            color = f"C{i}"
            settle = f"{m.settling_time_s * 1000:.0f} ms" if m.settling_time_s is not None else "never"
            label = f"{resp.label}: kp {resp.gains.kp:g} ki {resp.gains.ki:g} kf {resp.gains.kf:g} ks {resp.gains.ks:g}"
            label += f"\n  overshoot {m.overshoot * 100:.1f} %, settles {settle}"
            ax_v.plot(resp.t_s * 1000, resp.speed_m_s, ".", color=color, alpha=0.25, markersize=3)
            ax_v.plot(resp.t_s * 1000, smooth(resp.speed_m_s), "-", color=color, label=label)
            ax_u.plot(resp.t_s * 1000, resp.effort, "-", color=color)
        first = trials[0][0]
        ax_v.plot(first.t_s * 1000, first.setpoint_m_s, "k--", linewidth=1, label="setpoint")
        ax_v.set_ylabel(f"wheel {first.wheel} speed (m/s)")
        ax_u.set_ylabel("effort (-1..1)")
        ax_v.legend(fontsize=7, loc="lower right")
        ax_v.grid(alpha=0.3)
        ax_u.grid(alpha=0.3)
        ax_v.set_xlim(-100, min(first.hold_s * 1000, 400))
    for ax in axes[-1]:
        ax.set_xlabel("time from the step (ms)")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=dpi)
    plt.close(fig)
    return out
