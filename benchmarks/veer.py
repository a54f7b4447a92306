"""How far a differential-drive robot keeps turning when a turn is followed at once by a straight run.

    python benchmarks/veer.py                       # the TB6612 robot, six turns (about 10 s)
    python benchmarks/veer.py --profile diffdrive-bts7960 --json veer.json

Each case holds wheel speeds (left, right) for `--turn` seconds, then 300 mm/s on both wheels for 2 s,
on the emulator's virtual clock. It reports the heading change during the straight part (the
emulator's truth) and splits it in two:

- *commanded*: what the firmware's ramped setpoints themselves turn, (right - left) / track
  integrated over the run: the ramp's share (docs/control.md, section 4, step 5);
- *controllers*: the rest, what the wheel PIDs add (integrals learned at the turn's speeds, the
  motors' own lag).

and the same with a 1 s pause at zero between the two (both wheels then start from rest together).
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

from host_sdk import PROFILES, Robot
from host_sdk.kinematics import DiffDrive

CASES = ((0, 60), (60, 0), (30, 90), (100, 200), (-60, 60), (150, 300))
STRAIGHT_MM_S = 300
STRAIGHT_S = 2.0
STEP_S = 0.01


@dataclass(frozen=True)
class Veer:
    left_mm_s: int
    right_mm_s: int
    veer_deg: float
    commanded_deg: float
    controllers_deg: float
    after_pause_deg: float


def _hold(robot: Robot, left: int, right: int, seconds: float, track_m: float) -> tuple[float, float]:
    """Hold the wheel speeds; return (truth heading change, commanded heading change) in radians."""
    emu = robot.emulator
    assert emu is not None
    theta0 = emu.truth.plant.theta_rad
    commanded = 0.0
    for _ in range(round(seconds / STEP_S)):
        robot.set_wheel_speeds(left / 1000, right / 1000)
        robot.sleep(STEP_S)
        firmware = emu.truth.firmware
        if firmware is not None:
            ramped = firmware.ramped_mm_s
            commanded += (ramped[1] - ramped[0]) / 1000 / track_m * STEP_S
    return math.remainder(emu.truth.plant.theta_rad - theta0, 2 * math.pi), commanded


def measure(profile: str, left: int, right: int, turn_s: float, pause_s: float) -> tuple[float, float]:
    with Robot.connect(f"emu://{profile}?clock=virtual") as robot:
        kinematics = robot.kinematics
        if not isinstance(kinematics, DiffDrive):
            raise SystemExit(f"{profile} is not a differential drive")
        robot.arm()
        _hold(robot, left, right, turn_s, kinematics.track_m)
        if pause_s:
            _hold(robot, 0, 0, pause_s, kinematics.track_m)
        return _hold(robot, STRAIGHT_MM_S, STRAIGHT_MM_S, STRAIGHT_S, kinematics.track_m)


def _seconds(text: str) -> float:
    value = float(text)
    if not 0.1 <= value <= 60.0:
        raise argparse.ArgumentTypeError(f"--turn {value:g} s: give 0.1..60 s")
    return value


def main() -> None:
    diff = sorted(name for name, p in PROFILES.items() if p.kinematics == "diff")
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--profile", choices=diff, default="diffdrive-tb6612", help="the robot (default diffdrive-tb6612)")
    ap.add_argument("--turn", type=_seconds, default=3.0, help="seconds of turning before the straight run (default 3)")
    ap.add_argument("--json", type=Path, help="also write the figures here")
    args = ap.parse_args()
    rows = []
    print(f"{args.profile}: {args.turn:g} s turning, then {STRAIGHT_MM_S} mm/s straight for {STRAIGHT_S:g} s\n")
    print(
        "| turn (left, right mm/s) | veer, deg | commanded by the ramps | by the controllers "
        "| after a 1 s pause at zero |"
    )
    print("|---|---|---|---|---|")
    for left, right in CASES:
        veer, commanded = measure(args.profile, left, right, args.turn, 0.0)
        paused, _ = measure(args.profile, left, right, args.turn, 1.0)
        row = Veer(left, right, *(round(math.degrees(a), 2) for a in (veer, commanded, veer - commanded, paused)))
        rows.append(row)
        print(
            f"| {left}, {right} | {row.veer_deg:+.2f} | {row.commanded_deg:+.2f} | {row.controllers_deg:+.2f} "
            f"| {row.after_pause_deg:+.2f} |"
        )
    if args.json:
        report = {
            "profile": args.profile,
            "turn_s": args.turn,
            "straight_mm_s": STRAIGHT_MM_S,
            "straight_s": STRAIGHT_S,
            "cases": [asdict(r) for r in rows],
        }
        args.json.write_text(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
