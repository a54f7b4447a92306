"""`roverlink ros2 --url URL [--profile NAME | --robot FILE] [--ros-args ...]`: the ROS 2 bridge node (docs/ros2.md).

rclpy is imported only here, when the command runs: without it the command says how to install
it, and every other command works without ROS.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from roverlink import say
from roverlink.interactive import add_profile_args, add_url_args
from roverlink.ros2 import INSTALL_HINT, missing_modules
from roverlink.sensors.options import add_sensor_args

_DESCRIPTION = __doc__.split("\n\n")[1]


def cmd_ros2(args: argparse.Namespace) -> int:
    """Run the ROS 2 bridge node: cmd_vel in; odom, tf, joint_states and diagnostics out."""
    missing = missing_modules()
    if missing:
        say.error(f"cannot import {', '.join(missing)}; {INSTALL_HINT}")
        return 2
    from roverlink.ros2.run import run  # noqa: PLC0415 (rclpy: only when the command runs)

    return run(args.ros_args or [], overrides(args))


def overrides(args: argparse.Namespace) -> dict[str, Any]:
    """The node's parameters the command line sets (they win over a parameters file)."""
    out: dict[str, Any] = {}
    if args.url is not None:
        out["url"] = args.url
    if args.profile is not None:
        out["profile"] = args.profile
    if args.robot is not None:
        out["robot_file"] = args.robot.path
    if args.allow_mismatch:
        out["allow_mismatch"] = True
    for option, parameter in (
        ("baud", "baud"),
        ("lidar", "lidar_url"),
        ("lidar_model", "lidar_model"),
        ("imu", "imu_url"),
        ("imu_baud", "imu_baud"),
    ):
        if getattr(args, option) is not None:
            out[parameter] = getattr(args, option)
    return out


def unknown_hint(unknown: list[str]) -> str:
    """Where ROS arguments given before --ros-args belong (roverlink.cli)."""
    if any(a in ("-p", "--param", "--params-file", "-r", "--remap") for a in unknown):
        return " (ROS arguments go after --ros-args: roverlink ros2 ... --ros-args -p NAME:=VALUE)"
    return ""


def main(argv: list[str] | None = None) -> int:
    """`roverlink ros2` as its own program (a console script for `ros2 run`; docs/ros2.md)."""
    parser = argparse.ArgumentParser(prog="roverlink ros2", description=_DESCRIPTION)
    _add_arguments(parser)
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    say.running(parser.prog)
    return cmd_ros2(args)


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    _add_arguments(sub.add_parser("ros2", help=cmd_ros2.__doc__, description=_DESCRIPTION))


def _add_arguments(p: argparse.ArgumentParser) -> None:
    # No URL as a first argument: what follows the options is ROS's (--ros-args ...).
    add_url_args(
        p, without="the url parameter, /dev/ttyACM0", positional=False, baud=None, baud_help="the baud parameter"
    )
    add_profile_args(p, help_text="reference robot (default: from the firmware)")  # + robot_file, allow_mismatch
    # The sensor options every command takes, as the parameters they set (lidar_url, imu_url...).
    add_sensor_args(p, ("lidar", "imu"), off=None)
    p.add_argument(
        "--ros-args",
        nargs=argparse.REMAINDER,
        default=[],
        help="ROS arguments, e.g. --ros-args -p publish_tf:=false --params-file roverlink.yaml -r __ns:=/robot1",
    )
    p.set_defaults(func=cmd_ros2)
