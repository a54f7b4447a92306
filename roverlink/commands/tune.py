"""`roverlink tune URL`: velocity step tests per wheel (robot on a stand), metrics, a plot comparing
the current gains with candidates, and with `--auto` gains proposed from a fitted model, applied
after confirmation, verified with a new step and saved to EEPROM if asked; with --robot FILE the
gains in use are written into the file's [pid] (shown, then asked), since every connect with the
file sets its gains.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

from host_sdk import PidGains, Robot, RobotDescription, RoverLinkError
from host_sdk.extras import MissingDependencyError, require
from protocol.generated.constants import FEEDBACK_HZ_MAX
from protocol.robotfile.model import GAIN_NAMES
from roverlink import robot_file_edit as edit
from roverlink import say
from roverlink.emulated import place_on_stand
from roverlink.interactive import ConsolePrompter, Progress, Prompter, add_robot_args, bar, connect
from roverlink.robot_file_edit import Value
from roverlink.tuning.design import Design
from roverlink.tuning.metrics import StepMetrics, StepResponse
from roverlink.tuning.plot import plot_steps
from roverlink.tuning.steps import wheel_count
from roverlink.tuning.tuner import Tuner, WheelReport

DEFAULT_SPEED_FRACTION = 0.4


def parse_gains(text: str) -> PidGains:
    """ "KP,KI,KD,KF[,KS]" (or "kp=1,ki=6,kf=1.5"; unnamed gains 0) as PidGains."""
    names = ("kp", "ki", "kd", "kf", "ks")
    values = dict.fromkeys(names, 0.0)
    parts = [p for p in text.replace(" ", "").split(",") if p]
    try:
        if all("=" in p for p in parts):
            for part in parts:
                key, value = part.split("=", 1)
                if key not in values:
                    raise ValueError(key)
                values[key] = float(value)
        elif len(parts) in (4, 5):
            values |= dict(zip(names, (float(p) for p in parts), strict=False))
        else:
            raise ValueError(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: gains as KP,KI,KD,KF[,KS] or kp=..,ki=..,kd=..,kf=..,ks=.."
        ) from None
    return PidGains(**values)


def _stand(robot: Robot, prompter: Prompter, speed: float) -> bool:
    prompter.say(
        f"Put the robot on a stand: its wheels will spin, one at a time, at up to {speed:.2f} m/s "
        "(and back to 0) for about 2 s per test."
    )
    if place_on_stand(robot, True):
        prompter.say("  (emulator: the robot is now on its stand)")
    return prompter.confirm("Are the wheels off the ground and free to spin?")


def _print_trials(report: WheelReport, out: list[str]) -> None:
    for trial in report.trials:
        g = trial.response.gains
        out.append(f"  {trial.response.label:<10} kp {g.kp:<7g} ki {g.ki:<7g} kd {g.kd:<5g} kf {g.kf:<7g} ks {g.ks:g}")
        out.append(f"             {trial.metrics.row()}")


def run_tune(robot: Robot, args: argparse.Namespace, prompter: Prompter) -> list[WheelReport]:
    """The tests of one `tune` run (the robot is armed inside, disarmed after)."""
    wheels = list(range(wheel_count(robot))) if args.wheel == "all" else [int(args.wheel)]
    progress = Progress()

    def told(text: str, fraction: float) -> None:
        progress.update(f"{text:<28} {bar(fraction)}")

    tuner = Tuner(robot, speed_m_s=args.speed, hold_s=args.hold, lift_ramp=not args.keep_ramp, progress=told)
    reports = []
    with tuner.session():
        for wheel in wheels:
            report = WheelReport(wheel)
            current = tuner.measure(wheel, robot.pid(wheel), "current")
            report.trials.append(current)
            for n, gains in enumerate(args.try_gains or [], 1):
                report.trials.append(tuner.measure(wheel, gains, f"try {n}"))
            if args.auto:
                report.auto = tuner.auto(wheel, current)
                report.trials.extend(report.auto.tried)
            reports.append(report)
    progress.done()
    return reports


def apply_proposals(
    robot: Robot, args: argparse.Namespace, reports: list[WheelReport], prompter: Prompter
) -> list[str]:
    """Apply the proposals (after confirmation), verify each with a new step; lines for the summary."""
    lines: list[str] = []
    proposals = [(r.wheel, r.auto.gains) for r in reports if r.auto is not None and r.auto.gains is not None]
    if not proposals:
        return ["no candidate settled faster than the gains in use: they stay"]
    if not prompter.confirm("Apply the proposed gains?"):
        return ["gains left as they were"]
    for wheel, gains in proposals:
        robot.set_pid(**dataclasses.asdict(gains), wheel=wheel)
    tuner = Tuner(robot, speed_m_s=args.speed, hold_s=args.hold, lift_ramp=not args.keep_ramp)
    with tuner.session():
        for wheel, gains in proposals:
            trial = tuner.measure(wheel, gains, "applied")
            lines.append(f"wheel {wheel}: applied, verified: {trial.metrics.row()}")
            next(r for r in reports if r.wheel == wheel).trials.append(trial)
    if args.save or prompter.confirm("Save the new gains to the board's EEPROM?"):
        robot.save_config()
        lines.append("saved to EEPROM")
    else:
        lines.append("not saved: the board goes back to its EEPROM gains when it resets")
    if robot.description is not None:
        lines += write_gains(robot, robot.description, prompter)
    return lines


def file_gains(robot: Robot, description: RobotDescription) -> dict[str, Value]:
    """The board's gains as the robot file's [pid] keys that differ from the file's: one number
    where every wheel has the same, else one per wheel channel."""
    wheels = [robot.pid(w) for w in range(description.drive.channels)]
    mine = [description.pid.of_wheel(w) for w in range(description.drive.channels)]
    values: dict[str, Value] = {}
    for i, name in enumerate(GAIN_NAMES):
        board = tuple(getattr(g, name) for g in wheels)
        if board == tuple(m[i] for m in mine):
            continue  # left as written (`ki = 6` stays, not `ki = 6.0`)
        values[name] = board[0] if len(set(board)) == 1 else board
    return values


def write_gains(robot: Robot, description: RobotDescription, prompter: Prompter) -> list[str]:
    """The gains in use into the robot file's [pid] (the change shown, then asked): every later
    connect with the file applies its gains, so gains kept only on the board would be undone."""
    path = description.path
    values = file_gains(robot, description)
    if not values:
        return [f"{path} [pid] already has these gains"]
    try:
        change = edit.plan(path, {"pid": values})
    except (OSError, ValueError) as exc:  # RobotFileError is a ValueError
        return [f"error: {path} was not changed: {exc}", _by_hand(values)]
    prompter.say("\n".join(change.diff()))
    if not prompter.confirm(f"Write the new gains to {path}?"):
        return [f"{path} not changed: the next connect with it sets its own gains again", _by_hand(values)]
    try:
        change.write()
    except OSError as exc:
        return [f"error: {path} was not changed: {exc}", _by_hand(values)]
    shown = ", ".join(f"{k} = {edit.toml_value(v)}" for k, v in values.items())
    return [f"written to {path} [pid]: {shown}"]


def _by_hand(values: dict[str, Value]) -> str:
    return "to keep them, set in [pid]: " + ", ".join(f"{k} = {edit.toml_value(v)}" for k, v in values.items())


def _feed_forward(design: Design) -> str:
    if design.line is not None:
        return design.line.describe()
    return f"the model's line ({design.line_note})" if design.line_note else "the model's line"


def _auto_lines(report: WheelReport) -> list[str]:
    auto = report.auto
    assert auto is not None
    lines = [
        f"  model: {auto.model.describe()}",
        f"  feed-forward: {_feed_forward(auto.design)}",
        f"  {auto.design.candidates} candidates ranked on the model (roverlink.tuning.design); "
        f"the best {len(auto.tried)} stepped on the robot",
    ]
    g = auto.gains
    if g is None:
        lines.append("  proposal: keep the current gains (no candidate settled faster with < 10 % overshoot)")
    else:
        assert auto.chosen is not None
        lines.append(
            f"  proposal: {auto.chosen.response.label}: kp {g.kp:g} ki {g.ki:g} kd {g.kd:g} kf {g.kf:g} ks {g.ks:g}"
        )
    return lines


def _plot(reports: list[WheelReport], path: Path, title: str) -> str:
    rows: list[list[tuple[StepResponse, StepMetrics]]] = [
        [(t.response, t.metrics) for t in r.trials if t.response.label != "applied"] for r in reports
    ]
    plot_steps(rows, path, title)
    return f"plot: {path}"


def cmd_tune(args: argparse.Namespace) -> int:
    """Step-test each wheel's speed loop; compare gains; --auto proposes, applies, verifies, saves."""
    prompter = ConsolePrompter(assume_yes=args.yes)
    if args.plot:  # drawn after minutes of step tests: know before them that it can be
        require("matplotlib", "plot", "the tune plot (--plot FILE.png; --plot '' draws none)")
    try:
        with connect(args, feedback_hz=FEEDBACK_HZ_MAX) as robot:  # every tick: the step's finest record
            limit = robot.config.max_wheel_speed_mm_s / 1000
            if args.speed is None:
                args.speed = round(limit * DEFAULT_SPEED_FRACTION, 2)
            if not 0 < args.speed <= limit:
                say.error(f"--speed {args.speed:g}: 0 < speed <= {limit:g} m/s (max_wheel_speed_mm_s)")
                return 2
            if not _stand(robot, prompter, args.speed):
                print("not tuned: the robot must be on a stand")
                return 1
            reports = run_tune(robot, args, prompter)
            lines: list[str] = []
            for report in reports:
                lines.append(f"wheel {report.wheel} (step 0 -> {args.speed:g} m/s):")
                _print_trials(report, lines)
                if report.auto is not None:
                    lines.extend(_auto_lines(report))
            print("\n".join(lines))
            if args.plot:
                name = robot.identity.robot_name or "robot"
                print(_plot(reports, Path(args.plot), f"{name}: velocity steps"))
            summary = apply_proposals(robot, args, reports, prompter) if args.auto else []
    except MissingDependencyError:
        raise  # cli.main names the extra
    except (RoverLinkError, EOFError, ValueError) as exc:
        say.error(f"{exc}")
        return 1
    except KeyboardInterrupt:
        print("\ninterrupted: the robot was stopped and its gains and ramp put back", file=sys.stderr)
        return 130
    print("\n".join(["summary:", *(f"  {line}" for line in summary or ["gains unchanged"])]))
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("tune", help=cmd_tune.__doc__, description=__doc__)
    add_robot_args(p)
    p.add_argument("--wheel", choices=["0", "1", "all"], default="all", help="which wheel (default all)")
    p.add_argument("--speed", type=float, default=None, help="step size in m/s (default 40 %% of the speed limit)")
    p.add_argument("--hold", type=float, default=1.0, help="how long each step is held, s (default 1)")
    p.add_argument(
        "--try",
        dest="try_gains",
        type=parse_gains,
        action="append",
        metavar="KP,KI,KD,KF[,KS]",
        help="candidate gains (KS omitted: 0)",
    )
    p.add_argument("--auto", action="store_true", help="identify a model, propose gains, apply them after asking")
    p.add_argument("--plot", default="tune.png", metavar="FILE.png", help="plot file (default tune.png; '' for none)")
    p.add_argument("--save", action="store_true", help="save applied gains to EEPROM without asking")
    p.add_argument("--keep-ramp", action="store_true", help="keep the board's accel/decel limits during the steps")
    p.add_argument(
        "--yes",
        action="store_true",
        help="answer yes to every question (robot on a stand, apply, write --robot FILE's [pid])",
    )
    p.set_defaults(func=cmd_tune)
