"""`roverlink teleop URL`: drive with the keyboard. Arrows or WASD drive while held (a key's
repeats keep the command alive; when they stop the robot stops), +/- change the speed step,
space stops, enter (or r) arms, x disarms, q quits. Speeds are fractions of the board's limit; the
SDK's kinematics turn them into wheel speeds or steering. The dashboard shows the setpoint
against the measured speeds. With a lidar (`--lidar`, or an emu:// URL's) the obstacle guard
slows and stops the robot short of what it sees; Shift with an arrow key drives without it.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from collections.abc import Iterator

from host_sdk import Robot, RoverLinkError
from host_sdk.autonomy.guard import LidarGuard
from host_sdk.extras import MissingDependencyError
from host_sdk.sensors import Lidar
from protocol.generated.constants import FEEDBACK_HZ_DEFAULT
from roverlink import say
from roverlink.dashboard import Dashboard, lines
from roverlink.interactive import add_robot_args, connect
from roverlink.sensors import add_sensor_args, choose_sensors
from roverlink.teleop import TeleopController


@contextlib.contextmanager
def obstacle_guard(args: argparse.Namespace, robot: Robot) -> Iterator[LidarGuard | None]:
    """The guard on the robot's lidar (None without one: said on stderr, as driving is unprotected)."""
    choice = choose_sensors(args, robot, ("lidar",))
    if choice.lidar is None:
        say.notice("no lidar (--lidar PORT, or [sensors.lidar] port in the --robot FILE): no obstacle protection")
        yield None
        return
    with Lidar.open(choice.lidar, choice.lidar_model) as lidar:
        try:
            guard = LidarGuard(robot, lidar)
        except RoverLinkError as exc:  # no footprint to guard: an unknown robot without a robot file
            say.notice(f"no obstacle protection: {exc} (give --robot FILE)")
            yield None
            return
        say.notice(f"obstacle guard on the {choice.lidar_model} on {choice.lidar}")
        guard.start()
        try:
            yield guard
        finally:
            guard.stop()


def cmd_teleop(args: argparse.Namespace) -> int:
    """Keyboard driving (arrows/WASD, +/- speed, space stop, enter arm, x disarm, q quit)."""
    if not sys.stdin.isatty():
        say.error("it reads the keyboard: run it in a terminal")
        return 2
    from roverlink.tui import TeleopApp  # noqa: PLC0415 (Textual is an extra, loaded for the terminal view only)

    try:
        with connect(args, feedback_hz=FEEDBACK_HZ_DEFAULT) as robot, obstacle_guard(args, robot) as guard:
            dashboard = Dashboard(robot)
            controller = TeleopController(robot, key_timeout_s=args.key_timeout, guard=guard)
            try:
                TeleopApp(dashboard, controller).run()
            finally:
                controller.close()
                robot.stop()
                dashboard.close()
            stats = robot.stats
            print("\n".join(lines(dashboard.snapshot())))
            print(f"summary: {stats.setpoints_sent} setpoints sent, {stats.feedback_received} FEEDBACK received")
    except MissingDependencyError:
        raise  # cli.main names the extra
    except RoverLinkError as exc:
        say.error(f"{exc}")
        return 1
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("teleop", help=cmd_teleop.__doc__, description=__doc__.split("\n\n")[0])
    add_robot_args(p)
    add_sensor_args(p, ("lidar",), off="--no-lidar")
    p.add_argument(
        "--key-timeout", type=float, default=0.6, help="s without a key repeat before the robot stops (default 0.6)"
    )
    p.set_defaults(func=cmd_teleop)
