"""`roverlink calibrate URL`: a guided calibration over the link, no re-flash: motor and encoder
directions, encoder counts per revolution, wheel diameter, track width (differential drive) or
steering centre and angle per servo step (Ackermann); a check drive; the configuration before and
after; saved to EEPROM after confirmation. On `emu://` the emulator's ground truth answers the
questions a person with a tape measure would. With an IMU (--imu PORT, or an emu:// URL's
imu=jy901) its yaw measures the turns instead of a person. With --robot FILE the robot file's
geometry is the start and the measured values go into its [calibration], the motor and encoder
directions and servo pulses found into [drive], [encoders] and [steering] (with how to rebuild the
firmware, which is built with them); the JSON file of -o is then written only when asked for.
"""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

from host_sdk import Robot, RobotConfig, RobotDescription, RobotFileError, RoverLinkError
from host_sdk.enums import Capability
from host_sdk.extras import MissingDependencyError
from host_sdk.sensors import Sensors
from protocol.generated.constants import FEEDBACK_HZ_DEFAULT
from roverlink import say
from roverlink.argtypes import usage_lines
from roverlink.calibration import (
    Calibration,
    CalibrationResult,
    EmulatorObserver,
    ImuObserver,
    Observer,
    observer_for,
    restore,
    save_file,
    verify,
)
from roverlink.calibration.robot_file import build_facts, measured, outside_section, write_measured
from roverlink.emulated import first_collision
from roverlink.interactive import ConsolePrompter, Progress, Prompter, add_robot_args, bar, connect
from roverlink.sensors import add_sensor_args, choose_sensors, open_sensors

DEFAULT_OUTPUT = Path("calibration.json")

SHOWN = (
    "motor_invert",
    "encoder_invert",
    "encoder_cpr",
    "wheel_diameter_um",
    "steering_center_cdeg",
    "steering_min_cdeg",
    "steering_max_cdeg",
    "servo_min_us",
    "servo_max_us",
)


def before_after(result: CalibrationResult) -> list[str]:
    """The calibrated values, before and after, as a table."""
    lines = [f"  {'value':<22} {'before':>10} {'after':>10}"]
    changed = {name: (a, b) for name, a, b in result.changes()}
    before: RobotConfig = result.config_before
    after: RobotConfig = result.config_after
    for name in SHOWN:
        a, b = getattr(before, name), getattr(after, name)
        if result.ackermann or not name.startswith(("steering", "servo")):
            lines.append(f"  {name:<22} {a!s:>10} {b!s:>10}" + ("  *" if name in changed else ""))
    if not result.ackermann:
        mark = "  *" if "track_m (host)" in changed else ""
        a_mm, b_mm = result.track_before_m * 1000, result.track_after_m * 1000
        lines.append(f"  {'track_mm (host)':<22} {a_mm:>10.1f} {b_mm:>10.1f}{mark}")
    return lines


def _check_drive(robot: Robot, robot_file: RobotDescription | None) -> None:
    """A robot file of another kind of drive than the board's: refused before anything moves."""
    if robot_file is None:
        return
    board_diff = bool(robot.identity.capabilities & Capability.DIFF_DRIVE)
    if board_diff != (robot_file.drive.kind == "differential"):
        board_kind = "differential" if board_diff else "ackermann"
        raise ValueError(
            f"{robot_file.path}: drive.kind = {robot_file.drive.kind!r} but the board on {robot.url} "
            f"drives {board_kind}: not this robot's file"
        )


def run_calibration(
    robot: Robot,
    args: argparse.Namespace,
    prompter: Prompter,
    sensors: Sensors | None = None,
    robot_file: RobotDescription | None = None,
) -> int:
    _check_drive(robot, robot_file)
    observer: Observer = observer_for(robot, prompter)
    if isinstance(observer, EmulatorObserver):
        prompter.say("(emulator: its ground truth plays the person with the tape measure)")
    if sensors is not None and sensors.imu is not None:
        observer = ImuObserver(observer, robot, sensors)
        prompter.say(f"(the IMU on {sensors.imu.port.url} measures the turns: keep it level and away from steel)")
    progress = Progress()
    track, wheelbase = None, None
    if robot_file is not None:  # the file's geometry is the start (the board stores no track or wheelbase)
        track = robot_file.track_m
        wheelbase = robot_file.geometry.wheelbase_m or None
    cal = Calibration(
        robot,
        observer,
        revolutions=args.revolutions,
        distance_m=args.distance,
        turns=args.turns,
        track_m=track,
        wheelbase_m=wheelbase,
        say=prompter.say,
        progress=lambda what, f: progress.update(f"{what:<28} {bar(f)}"),
        tick=sensors.poll if sensors is not None else None,
    )
    try:
        result = cal.run()
        checks = verify(cal, result) if args.check else []
    finally:
        progress.done()
    lines = ["findings:", *(f"  {f}" for f in result.findings), "configuration (* changed):", *before_after(result)]
    if checks:
        lines += ["check with the new values:", *(f"  {c.line()}" for c in checks)]
    print("\n".join(lines))
    code, summary = 0, list[str]()
    if prompter.confirm("Keep the new values and save them to the board's EEPROM?"):
        code, summary = _keep(robot, args, result, robot_file)
    else:
        restore(robot, result.config_before)
        summary.append("the board's configuration was put back as it was")
    worst = max((c.error for c in checks), default=None)
    if worst is not None:
        summary.append(f"odometry vs measured after calibration: worst {worst * 100:.2f} %")
    print("\n".join(["summary:", *(f"  {s}" for s in summary)]))
    return code


def _keep(
    robot: Robot, args: argparse.Namespace, result: CalibrationResult, robot_file: RobotDescription | None
) -> tuple[int, list[str]]:
    """Save to EEPROM, then the host's files: the robot file's [calibration] (--robot), the JSON
    calibration file (-o, or by default without --robot). (exit code, summary lines)"""
    robot.save_config()
    summary = ["board configuration saved to EEPROM"]
    code = 0
    if robot_file is not None:
        try:
            summary += write_robot_file(robot_file, result, robot.url)
        except (OSError, ValueError) as exc:
            summary.append(f"error: the robot file was not changed: {exc}")
            summary += by_hand(robot_file, result)
            code = 1
    if args.output is not None or robot_file is None:
        name = robot.identity.robot_name or "robot"
        path = save_file(args.output or DEFAULT_OUTPUT, result, name)
        kept = "" if result.ackermann else " (with the track width, which the board does not store)"
        summary.append(f"kinematics{kept} written to {path}")
        summary += usage_lines(path, robot.url)
    return code, summary


def by_hand(robot_file: RobotDescription, result: CalibrationResult) -> list[str]:
    """What the calibration found, as the lines to set in the robot file by hand (its write failed)."""
    shown = ", ".join(f"{k} = {v}" for k, v in measured(result, robot_file).items())
    return ["to keep what was measured, set in the robot file:", f"  [calibration] {shown}"] + [
        f"  {line}" for line in outside_section(result, robot_file)
    ]


def write_robot_file(robot_file: RobotDescription, result: CalibrationResult, url: str) -> list[str]:
    """The measured values into the robot file's [calibration], the directions and servo pulses
    found into their own sections; summary lines."""
    values = measured(result, robot_file)
    facts = build_facts(result, robot_file)
    path = write_measured(robot_file.path, values, facts)
    shown = ", ".join(f"{k} = {v}" for k, v in values.items())
    lines = [
        f"measured values written to {path} [calibration]: {shown}",
        f"and in code: Robot.connect({url!r}, kinematics=host_sdk.RobotDescription.load({str(path)!r}).kinematics())",
    ]
    notes = outside_section(result, robot_file)
    if notes:
        # Directions and pulses are compiled into the firmware (and compared at connect): the board
        # has them in EEPROM now, but a blank or reset EEPROM falls back to the old build's.
        lines.append(f"also written to {path}, what the firmware is built with:")
        lines += [f"  {note}" for note in notes]
        port = shlex.quote(url) if "://" not in url else "PORT"  # a serial port, or the board's to come
        lines.append(
            f"rebuild and flash the firmware from the file to make them its defaults: "
            f"roverlink firmware flash --robot {shlex.quote(str(path))} --port {port}"
        )
    return lines


def cmd_calibrate(args: argparse.Namespace) -> int:
    """Guided calibration: directions, counts per revolution, wheel diameter, track or steering."""
    prompter = ConsolePrompter(assume_yes=args.yes)
    robot_file = None
    if getattr(args, "robot", None) is not None:
        try:  # read and checked before connecting: a bad file drives nothing
            robot_file = RobotDescription.load(Path(getattr(args.robot, "path", args.robot)))
        except RobotFileError as exc:
            say.error(exc)
            return 2
    try:
        with (
            connect(args, feedback_hz=FEEDBACK_HZ_DEFAULT) as robot,
            open_sensors(choose_sensors(args, robot, kinds=("imu",))) as sensors,
        ):
            try:
                return run_calibration(robot, args, prompter, sensors, robot_file)
            except RoverLinkError:
                hit = first_collision(robot)
                if hit is not None:  # the emulated robot drove into its world: say so, not just the failsafe
                    say.error(f"the emulated robot hit {hit}: give it room (world=empty)")
                raise
    except MissingDependencyError:
        raise  # cli.main names the extra
    except (RoverLinkError, EOFError, ValueError, TimeoutError, OSError) as exc:
        say.error(f"{exc}")
        return 1
    except KeyboardInterrupt:
        print("\nstopped: the robot was stopped; nothing was saved to EEPROM", file=sys.stderr)
        return 130


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("calibrate", help=cmd_calibrate.__doc__, description=__doc__)
    add_robot_args(p)
    p.add_argument("--revolutions", type=float, default=5.0, help="wheel turns to count per wheel (default 5)")
    p.add_argument("--distance", type=float, default=2.0, help="straight drive to measure, m (default 2)")
    p.add_argument("--turns", type=float, default=1.0, help="in-place turns to measure (default 1)")
    p.add_argument("--no-check", dest="check", action="store_false", help="skip the check drive at the end")
    if not any("--robot" in a.option_strings for a in p._actions):  # unless the common robot arguments have it
        p.add_argument(
            "--robot",
            type=Path,
            default=None,
            metavar="FILE",
            help="robot file (docs/robot-file.md): start from its geometry, write the measured values "
            "into its [calibration]",
        )
    p.add_argument(
        "-o",
        "--output",
        type=Path,
        default=None,
        help=f"host calibration file, JSON kinematics (default {DEFAULT_OUTPUT} without --robot)",
    )
    p.add_argument("--yes", action="store_true", help="keep and save the result without asking")
    add_sensor_args(p, kinds=("imu",), off="--no-imu")
    p.set_defaults(func=cmd_calibrate)
