"""The tuning procedure: measure the current gains, try candidates, identify a model and propose.

tuner = Tuner(robot, speed_m_s=0.3)
with tuner.session():                        # armed, setpoint ramp lifted; all restored after
    current = tuner.measure(0, robot.pid(0), "current")
    model, design, _ = tuner.identify(0)        # open-loop step, held efforts, candidates
    auto = tuner.measure(0, design.gains, "auto")
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

from host_sdk import PidGains, Robot
from roverlink.tuning.design import Design, design_gains
from roverlink.tuning.feedforward import HELD_HIGH_S, HELD_LOW, HELD_LOW_S, LineError, StaticLine, held_line
from roverlink.tuning.fopdt import Fopdt, fit_fopdt, simc_gains
from roverlink.tuning.metrics import SETTLING_BAND, StepMetrics, StepResponse, mean_metrics, step_metrics
from roverlink.tuning.steps import free_ramp, gains_applied, run_step

MAX_OVERSHOOT = 0.10
CLEAR_OF_BAND = 0.8
"""Proposals prefer a measured overshoot under 80 % of the settling band (4 % of the step)."""
IDENTIFY_LOW = 0.5
"""The open-loop test first runs at this fraction of the test speed's feed-forward effort."""


@dataclass
class Trial:
    response: StepResponse
    """The first step (what the plot shows)."""
    metrics: StepMetrics
    """Over all the steps (roverlink.tuning.metrics.mean_metrics)."""
    steps: int = 1


@dataclass
class AutoResult:
    model: Fopdt
    design: Design
    tried: list[Trial]
    """The model's best candidates, as measured on the robot."""
    chosen: Trial | None
    """The proposal (None: none beat the gains in use; keep them)."""

    @property
    def gains(self) -> PidGains | None:
        return self.chosen.response.gains if self.chosen is not None else None


def better(trial: Trial, than: Trial) -> bool:
    """Settled at least as fast as `than`, with under 10 % overshoot."""
    m, ref = trial.metrics, than.metrics
    if m.settling_time_s is None or m.overshoot >= MAX_OVERSHOOT:
        return False
    return ref.settling_time_s is None or m.settling_time_s <= ref.settling_time_s


@dataclass
class WheelReport:
    wheel: int
    trials: list[Trial] = field(default_factory=list)
    auto: AutoResult | None = None

    def trial(self, label: str) -> Trial | None:
        return next((t for t in self.trials if t.response.label == label), None)


class Tuner:
    """Step tests on a robot on a stand. `progress(text, fraction)` is told how each test goes."""

    def __init__(
        self,
        robot: Robot,
        *,
        speed_m_s: float,
        hold_s: float = 1.0,
        repeats: int = 3,
        lift_ramp: bool = True,
        progress: Callable[[str, float], None] | None = None,
    ) -> None:
        self.robot = robot
        self.speed_m_s = speed_m_s
        self.hold_s = hold_s
        self.repeats = repeats
        self.lift_ramp = lift_ramp
        self.progress = progress

    @contextlib.contextmanager
    def session(self) -> Iterator[None]:
        """Armed, with the setpoint ramp lifted (unless lift_ramp=False); stopped, disarmed and the
        ramp restored afterwards, also on errors and Ctrl-C."""
        robot = self.robot
        with free_ramp(robot, self.lift_ramp):
            robot.arm()
            try:
                yield
            finally:
                robot.stop()
                robot.disarm()

    def _step(
        self,
        wheel: int,
        gains: PidGains,
        label: str,
        speed: float,
        *,
        start: float = 0.0,
        before_s: float = 0.3,
        hold_s: float | None = None,
    ) -> StepResponse:
        def told(fraction: float) -> None:
            if self.progress is not None:
                self.progress(f"wheel {wheel}: {label}", fraction)

        with gains_applied(self.robot, wheel, gains):
            return run_step(
                self.robot,
                wheel,
                speed,
                label=label,
                gains=gains,
                start_m_s=start,
                before_s=before_s,
                hold_s=self.hold_s if hold_s is None else hold_s,
                on_progress=told,
            )

    def measure(self, wheel: int, gains: PidGains, label: str) -> Trial:
        """Closed-loop steps from rest to the test speed with `gains` (then the wheel's own again).
        `repeats` steps: one step's settling time varies by about a control tick with where the
        encoder edges fall, so the metrics are averaged."""
        responses = [self._step(wheel, gains, label, self.speed_m_s) for _ in range(self.repeats)]
        return Trial(responses[0], mean_metrics([step_metrics(r) for r in responses]), len(responses))

    def identify(self, wheel: int, kf: float | None = None) -> tuple[Fopdt, Design, StepResponse]:
        """Open-loop effort step (kf only), the model fitted to it, the efforts the wheel holds at
        two speeds (the feed-forward line, roverlink.tuning.feedforward), and the gains the tuning
        rule (roverlink.tuning.design) proposes for them."""
        if kf is None or kf <= 0:
            kf = self.robot.pid(wheel).kf or 1.0
        open_loop = PidGains(kp=0.0, ki=0.0, kd=0.0, kf=kf)
        low = self.speed_m_s * IDENTIFY_LOW
        response = self._step(wheel, open_loop, "open loop", self.speed_m_s, start=low)
        u1 = kf * low * 1000
        u2 = kf * self.speed_m_s * 1000
        hold = response.t_s < self.hold_s
        model = fit_fopdt(response.t_s[hold], response.speed_m_s[hold] * 1000, u1, u2)
        line, why = self._held_line(wheel, model)
        design = design_gains(
            model,
            self.speed_m_s * 1000,
            self.robot.config.max_effort_permille,
            current=self.robot.pid(wheel),
            line=line,
        )
        if why:
            design = dataclasses.replace(design, line_note=why)
        return model, design, response

    def _held_line(self, wheel: int, model: Fopdt) -> tuple[StaticLine | None, str]:
        """The efforts held at 10 % of the test speed and at the test speed under SIMC's PI on the
        model; (None, why) when the holds missed their speeds."""
        held = self._step(
            wheel,
            simc_gains(model),
            "held",
            self.speed_m_s,
            start=self.speed_m_s * HELD_LOW,
            before_s=HELD_LOW_S,
            hold_s=max(self.hold_s, HELD_HIGH_S),
        )
        try:
            return held_line(held), ""
        except LineError as exc:
            return None, str(exc)

    def auto(self, wheel: int, current: Trial) -> AutoResult:
        """Identify, rank candidates on the model, step the best ones on the robot, and choose
        the fastest that beats `current` (the gains in use, measured): docs in roverlink.tuning.design."""
        model, design, _ = self.identify(wheel)
        tried = []
        for n, gains in enumerate(design.ranked, 1):
            tried.append(self.measure(wheel, gains, f"auto {n}"))
        good = [t for t in tried if better(t, current)]
        # A peak near the edge of the settling band makes the settling time jump by the overshoot's
        # ringing from one step to the next: prefer candidates clear of it.
        clear = [t for t in good if t.metrics.overshoot < CLEAR_OF_BAND * SETTLING_BAND]
        chosen = min(clear or good, key=lambda t: t.metrics.settling_time_s or 0.0, default=None)
        return AutoResult(model, design, tried, chosen)
