"""Read and change the velocity PID gains, and watch the step response change.

.venv/bin/python examples/tune_pid.py                                          # the emulated diff-drive car
.venv/bin/python examples/tune_pid.py "emu://diffdrive-bts7960?clock=virtual"  # the SLAM robot (lockstep)
.venv/bin/python examples/tune_pid.py "emu://picar?clock=virtual"              # the PiCar (one wheel: its ESC)
.venv/bin/python examples/tune_pid.py /dev/ttyACM0                             # a real board

drive(speed, 0) works on every robot (set_wheel_speeds() is for differential drives only).
"""

from __future__ import annotations

import dataclasses
import sys

from host_sdk import Robot


def step_response(robot: Robot, target_m_s: float = 0.3, seconds: float = 1.0) -> float:
    """Mean speed error of the left wheel over a speed step, in m/s (lower is better)."""
    errors = []
    end = robot.now() + seconds
    while robot.now() < end:
        robot.drive(target_m_s, 0.0)
        errors.append(abs(robot.wait_feedback().wheel_speeds_m_s[0] - target_m_s))
    for _ in range(40):
        robot.stop()
        robot.wait_feedback()
    return sum(errors) / len(errors)


def main(url: str = "emu://") -> None:
    with Robot.connect(url) as robot:
        before = robot.pid(0)
        print(f"gains now: kp={before.kp} ki={before.ki} kd={before.kd} kf={before.kf} ks={before.ks}")
        robot.arm()
        print(f"mean speed error, default gains:    {step_response(robot) * 1000:.1f} mm/s")
        robot.disarm()
        after = robot.set_pid(kp=before.kp / 4, ki=before.ki / 4, kf=before.kf / 2, ks=0.0)  # every wheel; verified
        print(f"gains set: kp={after.kp} ki={after.ki} kf={after.kf} ks={after.ks}")
        robot.arm()
        print(f"mean speed error, detuned gains:    {step_response(robot) * 1000:.1f} mm/s")
        robot.disarm()
        robot.set_pid(**dataclasses.asdict(before))  # back (save_config() would make gains stick)


if __name__ == "__main__":
    main(*sys.argv[1:2])
