"""Velocity step tests on one wheel at a time, through the SDK, at the feedback rate.

The robot is on a stand: one wheel steps while the other is held at zero. Every FEEDBACK sample
is kept (`on_feedback`); the loop renews the setpoint once per sample, so a lockstep board is paced
the same way. t = 0 is the control tick that applied the step (the first sample whose effort
moved), on the MCU's clock.
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Callable, Iterator

import numpy as np

from host_sdk import FeedbackSample, PidGains, Robot, RoverLinkError
from host_sdk.enums import Capability, Status
from roverlink.tuning.metrics import StepResponse

RAMP_FREE_MM_S2 = 65535
"""accel/decel limits while testing: the setpoint reaches its step within one 10 ms tick."""


class TuningError(RoverLinkError, RuntimeError):
    """A step test that could not run or gave no answer."""


def wheel_count(robot: Robot) -> int:
    """Driven wheels with their own speed loop: 2 for differential drive, 1 for Ackermann."""
    return 2 if robot.identity.capabilities & Capability.DIFF_DRIVE else 1


def command_wheel(robot: Robot, wheel: int, speed_m_s: float) -> None:
    """Run one wheel at `speed_m_s` (the other, if any, at zero; Ackermann steering centred)."""
    if robot.identity.capabilities & Capability.DIFF_DRIVE:
        speeds = (speed_m_s, 0.0) if wheel == 0 else (0.0, speed_m_s)
        robot.set_wheel_speeds(*speeds)
    else:
        robot.drive_ackermann(speed_m_s, 0.0)


@contextlib.contextmanager
def free_ramp(robot: Robot, lift: bool = True) -> Iterator[None]:
    """Lift the board's setpoint ramp (accel/decel limits) for the block, so a step is a step and
    the test measures the speed loop; the old limits are put back however the block ends."""
    if not lift:
        yield
        return
    config = robot.read_config()
    old = {"accel_limit_mm_s2": config.accel_limit_mm_s2, "decel_limit_mm_s2": config.decel_limit_mm_s2}
    robot.set_config(accel_limit_mm_s2=RAMP_FREE_MM_S2, decel_limit_mm_s2=RAMP_FREE_MM_S2)
    try:
        yield
    finally:
        robot.set_config(**old)


@contextlib.contextmanager
def gains_applied(robot: Robot, wheel: int, gains: PidGains) -> Iterator[None]:
    """`gains` on `wheel` for the block, the wheel's own gains again afterwards."""
    old = robot.pid(wheel)
    robot.set_pid(**dataclasses.asdict(gains), wheel=wheel)
    try:
        yield
    finally:
        robot.set_pid(**dataclasses.asdict(old), wheel=wheel)


def run_step(
    robot: Robot,
    wheel: int,
    speed_m_s: float,
    *,
    label: str,
    gains: PidGains,
    start_m_s: float = 0.0,
    before_s: float = 0.3,
    hold_s: float = 1.0,
    after_s: float = 0.4,
    on_progress: Callable[[float], None] | None = None,
) -> StepResponse:
    """Hold `start_m_s`, step to `speed_m_s` for `hold_s`, then back to zero; every sample kept."""
    samples: list[FeedbackSample] = []
    unsubscribe = robot.on_feedback(samples.append)
    try:
        phases = ((start_m_s, before_s), (speed_m_s, hold_s), (0.0, after_s))
        step_sent_index = 0
        total = before_s + hold_s + after_s
        begin = robot.now()
        for n, (setpoint, duration) in enumerate(phases):
            if n == 1:
                step_sent_index = len(samples)
            end = robot.now() + duration
            while robot.now() < end:
                command_wheel(robot, wheel, setpoint)
                robot.wait_feedback(0.5)
                if on_progress is not None:
                    on_progress(min(1.0, (robot.now() - begin) / total))
        robot.stop()
    finally:
        unsubscribe()
    return _response(
        samples, step_sent_index, wheel, label, gains, start_m_s=start_m_s, speed_m_s=speed_m_s, hold_s=hold_s
    )


def _response(
    samples: list[FeedbackSample],
    step_index: int,
    wheel: int,
    label: str,
    gains: PidGains,
    *,
    start_m_s: float,
    speed_m_s: float,
    hold_s: float,
) -> StepResponse:
    if len(samples) < 10 or step_index == 0:
        raise TuningError(f"step test on wheel {wheel}: only {len(samples)} FEEDBACK samples arrived")
    effort = np.array([s.efforts[wheel] for s in samples])
    before = effort[step_index - 1]
    moved = np.nonzero(np.abs(effort[step_index:] - before) > 0.0005)[0]
    if len(moved) == 0:
        raise TuningError(f"step test on wheel {wheel}: the effort never changed (is the robot armed? in failsafe?)")
    i0 = step_index + int(moved[0])
    t0 = samples[i0].mcu_time_us
    t = np.array([(s.mcu_time_us - t0) / 1e6 for s in samples])
    setpoint = np.where((t >= 0) & (t < hold_s), speed_m_s, np.where(t < 0, start_m_s, 0.0))
    return StepResponse(
        wheel=wheel,
        gains=gains,
        label=label,
        step_m_s=speed_m_s - start_m_s,
        hold_s=hold_s,
        t_s=t,
        setpoint_m_s=setpoint.astype(np.float64),
        speed_m_s=np.array([s.wheel_speeds_m_s[wheel] for s in samples]),
        effort=effort,
        saturated=np.array([bool(s.status & Status.SATURATED) for s in samples]),
    )
