"""`roverlink robot`: make (`new`), check and explain a robot file (docs/robot-file.md).

roverlink robot new my.toml --from picar   # a commented copy of a reference robot
roverlink robot new my.toml --from picar --board pico  # the same robot wired to a Raspberry Pi Pico
roverlink robot check my.toml              # exit 0 "my.toml: ok", or 2 and every problem
roverlink robot show my.toml               # the figures the firmware and the host derive
roverlink robot ros2-config my.toml --out config/  # the node's, SLAM Toolbox's and Nav2's parameters
roverlink robot urdf my.toml -o my.urdf    # a URDF for robot_state_publisher (docs/ros2.md)
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from host_sdk import RobotDescription
from protocol.robotfile import REFERENCES, RobotFileError, check, reference_path
from protocol.robotfile.pico import on_pico
from roverlink import say
from roverlink.commands.info import capabilities_text

# `roverlink firmware build --example NAME` flash sizes of the reference firmwares (avr-gcc 5.4.0;
# tests/firmware/test_avr_build.py fails when a build drifts 2 % from them): the one a robot file's
# firmware is built from stands in for it until it is built.
REFERENCE_FLASH = {
    ("uno", "ESC+servo"): ("AckermannPiCar", 15_296),
    ("mega2560", "TB6612"): ("DiffDriveTB6612", 17_894),
    ("mega2560", "L298N"): ("DiffDriveTB6612", 17_894),
    ("mega2560", "BTS7960"): ("DiffDriveBTS7960", 16_958),
}
# The same for the Pico: each reference robot's build on its driver's Pico pinout (the Pico program;
# tests/firmware/test_rp2040_firmware.py holds them to 2 % of the builds).
PICO_FLASH = {
    "ESC+servo": ("picar", 16_816),
    "TB6612": ("diffdrive-tb6612", 16_820),
    "L298N": ("diffdrive-tb6612", 16_820),
    "BTS7960": ("diffdrive-bts7960", 16_828),
}
FLASH_SIZE = {"uno": 32_256, "mega2560": 253_952, "pico": 2 * 1024 * 1024}  # bytes left by a bootloader


def cmd_new(args: argparse.Namespace) -> int:
    target = Path(args.file)
    if target.exists() and not args.force:
        say.error(f"{target} exists (--force to overwrite)")
        return 1
    text = reference_path(args.source).read_text(encoding="utf-8")
    # The copy is the user's own file: the reference's opening comment (what the reference robot
    # is the source of) does not apply to it.
    lines = text.splitlines(keepends=True)
    opening = next((i for i, line in enumerate(lines) if not line.startswith("#")), len(lines))
    header = [
        f"# Your robot, started from the reference robot {args.source} (the format: docs/robot-file.md).\n",
        f"# Change it, then `roverlink robot check {target}`; `name` is what firmware built from it reports.\n",
    ]
    body = "".join(lines[opening:])
    if args.board == "pico":  # the same robot on the Pico pinout (docs/firmware.md, Raspberry Pi Pico)
        body = on_pico(body, str(target))
    target.write_text("".join(header) + body, encoding="utf-8")
    on = " on the Pico pinout" if args.board == "pico" else ""
    print(f"{target}: a copy of {args.source}{on}; change it, then `roverlink robot check {target}`")
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    problems = check(args.file)
    if problems:
        for problem in problems:  # FILE:LINE: key: ..., as compilers and linters write them
            print(problem)
        say.error(f"{args.file}: {len(problems)} problem{'s' if len(problems) > 1 else ''}")
        return 2
    print(f"{args.file}: ok")
    return 0


def _flash(robot: RobotDescription) -> str:
    if robot.board == "pico":
        pico = PICO_FLASH.get(robot.drive.driver)
        ref = None if pico is None else (pico[1], f"{pico[0]} on the Pico's build")
    else:
        avr = REFERENCE_FLASH.get((robot.board, robot.drive.driver))
        ref = None if avr is None else (avr[1], f"the {avr[0]} example's build")
    if ref is None:
        return "no reference build to estimate from"
    size, what = ref
    share = 100 * size / FLASH_SIZE[robot.board]
    return (
        f"about {size:,} B ({share:.{1 if share < 10 else 0}f}% of {FLASH_SIZE[robot.board]:,} B): {what}, not "
        f"this file's; `roverlink firmware build --robot {robot.path}` prints its own"
    )


def _load(name: str) -> RobotDescription | None:
    """A robot file, or a reference robot's name (when no file of that name exists); None after
    printing what is wrong and how to fix it."""
    try:
        if name in REFERENCES and not Path(name).exists():
            return RobotDescription.load(reference_path(name))
        return RobotDescription.load(name)
    except RobotFileError as exc:
        fix = (
            f"give a robot file (`roverlink robot new {name} --from NAME` starts one) or a reference robot: "
            + ", ".join(REFERENCES)
            if not Path(name).exists()
            else f"fix the file (`roverlink robot check {name}` lists the same problems)"
        )
        say.error(f"{exc}\n{fix}")
        return None


def cmd_show(args: argparse.Namespace) -> int:
    robot = _load(args.file)
    if robot is None:
        return 2
    config = robot.config()
    wheel_rps = robot.limits.max_wheel_speed_m_s / (math.pi * robot.wheel_diameter_m)
    print(f"{robot.name}: {robot.drive.kind} drive ({robot.drive.driver}) on the {robot.board}")
    print(f"  metres per count      {robot.metres_per_count * 1000:.4f} mm ({robot.counts_per_rev} counts/rev)")
    print(f"  max wheel speed       {robot.limits.max_wheel_speed_m_s:g} m/s ({wheel_rps * 60:.0f} rpm)")
    print(f"  kinematics            {robot.kinematics()}")
    print(f"  capabilities          {capabilities_text(robot.capabilities())}")
    w = robot.wiring
    pins = [f"{m.kind} {i}: " + ", ".join(f"{r} {p}" for r, p in m.pins) for i, m in enumerate(w.motors)]
    pins += [f"encoder {i}: " + ", ".join(f"{r} {p}" for r, p in e.pins) for i, e in enumerate(w.encoders)]
    pins += [f"{name} {pin}" for name, pin in (("esc", w.esc_pin), ("servo", w.servo_pin)) if pin is not None]
    pins += [f"leds {', '.join(map(str, w.led_pins))}"] if w.led_pins else []
    pico = robot.board == "pico"
    pins.append("entropy the ring oscillator (entropy_pin is not read)" if pico else f"entropy {w.entropy_pin}")
    print("  pins                  " + "\n                        ".join(pins))
    print(f"  SET_CONFIG            {config}")
    print(f"  flash (estimate)      {_flash(robot)}")
    print("  SRAM (estimate)       under half of the board's, as every reference build (docs/budgets.md)")
    return 0


def cmd_ros2_config(args: argparse.Namespace) -> int:
    from roverlink.ros2.configs import warnings, write  # noqa: PLC0415 (only this action needs it)

    robot = _load(args.file)
    if robot is None:
        return 2
    if args.max_speed is not None and args.max_speed <= 0:
        say.error(f"--max-speed {args.max_speed:g}: must be > 0 m/s")
        return 2
    for path in write(robot, Path(args.out), args.max_speed, args.odom_topic):
        print(path)
    for line in warnings(robot, args.odom_topic):
        print(f"warning: {line}", file=sys.stderr)
    return 0


def cmd_urdf(args: argparse.Namespace) -> int:
    from roverlink.ros2.urdf import build_urdf  # noqa: PLC0415 (only this action needs it)

    robot = _load(args.file)
    if robot is None:
        return 2
    text = build_urdf(robot)
    if args.output is None:
        sys.stdout.write(text)
        return 0
    Path(args.output).write_text(text, encoding="utf-8")
    print(f"{args.output}: URDF of {robot.name}; publish it with robot_state_publisher (docs/ros2.md)")
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser(
        "robot",
        help="make (robot new), check and explain a robot file",
        description="A robot file describes your robot (docs/robot-file.md): start one from a reference robot, "
        "check it, show what the firmware and the host derive from it.",
    )
    actions = p.add_subparsers(dest="action", required=True, metavar="ACTION")
    new = actions.add_parser(
        "new",
        help="write a commented copy of a reference robot's file",
        description="Write FILE: a reference robot's file with every key explained, to change for your robot.",
    )
    new.add_argument("file", help="the robot file to write")
    new.add_argument("--from", dest="source", choices=REFERENCES, required=True, help="the reference robot")
    new.add_argument(
        "--board",
        choices=("pico",),
        help="move the robot to this board: pico puts its drive on the Pico pinout (docs/firmware.md)",
    )
    new.add_argument("--force", action="store_true", help="overwrite an existing file")
    new.set_defaults(func=cmd_new)
    chk = actions.add_parser(
        "check",
        help="exit 0 if the file is fine, else 2 listing every problem",
        description="Check FILE: prints 'FILE: ok' (exit 0), or every problem with its line (exit 2).",
    )
    chk.add_argument("file", help="the robot file to check")
    chk.set_defaults(func=cmd_check)
    show = actions.add_parser(
        "show",
        help="print the derived figures (metres per count, speeds, pins, flash)",
        description="What the firmware and the host derive from FILE: metres per count, the fastest wheel "
        "speed, kinematics, pins per function, SET_CONFIG, and a flash/SRAM estimate from the reference builds.",
    )
    show.add_argument("file", help="the robot file to explain")
    show.set_defaults(func=cmd_show)
    urdf = actions.add_parser(
        "urdf",
        help="write a URDF of the robot for robot_state_publisher",
        description="A URDF of FILE (a robot file, or a reference robot's name): base_link at the pose point on "
        "the ground, base_footprint, the body from the footprint, the wheels on the joints the ROS 2 node's "
        "joint_states names, and each sensor's frame at its mount (docs/ros2.md).",
    )
    urdf.add_argument("file", help=f"the robot file, or a reference robot: {', '.join(REFERENCES)}")
    urdf.add_argument("-o", "--output", default=None, metavar="OUT", help="write it here (default: print it)")
    urdf.set_defaults(func=cmd_urdf)
    _add_ros2_config(actions)


def _add_ros2_config(actions: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    from roverlink.ros2.robotfacts import FILTERED_ODOM, TOPICS  # noqa: PLC0415 (plain Python, no ROS)

    cfg = actions.add_parser(
        "ros2-config",
        help="write the ROS 2 node's, SLAM Toolbox's and Nav2's parameters files for the robot",
        description="Write roverlink.yaml, slam_toolbox.yaml and nav2.yaml into OUT for FILE's robot: its "
        "footprint, speed and acceleration limits, a car's tightest turn, its lidar (docs/ros2.md).",
    )
    cfg.add_argument("file", help="the robot file")
    cfg.add_argument("--out", "-o", default=".", help="the folder to write into (default: here)")
    cfg.add_argument(
        "--max-speed", type=float, default=None, help="m/s Nav2 may ask for (default: the file's max wheel speed)"
    )
    cfg.add_argument(
        "--odom-topic",
        choices=(TOPICS["odom"], FILTERED_ODOM),
        default=TOPICS["odom"],
        help="Nav2's odometry: the node's odom, or an EKF's odometry/filtered",
    )
    cfg.set_defaults(func=cmd_ros2_config)
