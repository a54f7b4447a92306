"""`roverlink monitor URL`: a live, read-only view of a robot: identity, state (armed, failsafe and
its reason), measured wheel speeds and efforts, steering, odometry, both sides' link statistics
with rates, RTT and clock drift, the firmware's LOG lines, and the sensors when there are any
(scan rate and points, nearest obstacle, IMU attitude and rates, camera fps and dropped frames).

It never arms or commands. It is the one program on the link: a serial port has one owner, and
the monitor's own session (HELLO) would end any other program's (the board disarms on a new
HELLO). To watch a robot that a program drives, record from that program (`--foxglove` on
`follow`, or `Recorder.attach` in your code). On a terminal it is a Textual app (`tui` extra);
when stdout is not a terminal it prints one line per period instead.
"""

from __future__ import annotations

import argparse
import sys

from host_sdk import Robot, RoverLinkError
from host_sdk.extras import MissingDependencyError
from host_sdk.recording import Recorder
from roverlink import say
from roverlink.commands.record import POLL_S, add_foxglove_args
from roverlink.dashboard import Dashboard, lines, one_line
from roverlink.interactive import add_robot_args, announce_live_view, connect
from roverlink.sensors import add_sensor_args, choose_sensors, open_sensors


def plain(robot: Robot, dashboard: Dashboard, period_s: float, duration_s: float | None, poll: object = None) -> int:
    """Periodic lines until `duration_s` (None: Ctrl-C); the whole view at the end."""
    start = robot.now()
    samples = 0
    try:
        while duration_s is None or robot.now() - start < duration_s - 1e-9:
            line_at = robot.now() + period_s
            # Poll in short steps: sensors on an emulator's virtual clock are read here.
            while (left := line_at - robot.now()) > 1e-9:
                robot.sleep(min(POLL_S, left))
                dashboard.poll()
                if callable(poll):
                    poll()
            samples += 1
            print(f"{robot.now() - start:7.1f} s  {one_line(dashboard.snapshot())}", flush=True)
    except KeyboardInterrupt:
        pass
    print("\n".join(lines(dashboard.snapshot())))
    return samples


def cmd_monitor(args: argparse.Namespace) -> int:
    """Live read-only view: state, wheels, odometry, link statistics, LOG lines."""
    tty = sys.stdout.isatty() and not args.plain
    if tty:  # before connecting: a missing Textual is named at once
        from roverlink.tui import DashboardApp  # noqa: PLC0415 (Textual is an extra, loaded for the terminal view only)
    try:
        with connect(args, feedback_hz=args.rate) as robot, open_sensors(choose_sensors(args, robot)) as sensors:
            recorder = None
            if args.foxglove:
                recorder = Recorder.attach(
                    robot,
                    serve=True,
                    host=args.foxglove_host,
                    port=args.foxglove_port,
                    board_stats=False,
                    sensors=sensors,
                )
                announce_live_view(recorder)
            else:
                sensors.start()
            dashboard = Dashboard(robot, sensors=sensors)
            poll = recorder.poll if recorder is not None else None
            try:
                if tty:
                    DashboardApp(dashboard, on_refresh=poll).run()
                    print("\n".join(lines(dashboard.snapshot())))
                else:
                    plain(robot, dashboard, args.period, args.duration, poll)
            finally:
                dashboard.close()
                if recorder is not None:
                    print("\n".join(recorder.close().lines()))
    except MissingDependencyError:
        raise  # cli.main names the extra
    except (RoverLinkError, OSError) as exc:
        say.error(f"{exc}")
        return 1
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("monitor", help=cmd_monitor.__doc__, description=__doc__.split("\n\n")[0])
    add_robot_args(p)
    p.add_argument("--rate", type=int, default=50, metavar="HZ", help="feedback rate asked of the board (default 50)")
    p.add_argument("--plain", action="store_true", help="periodic lines even on a terminal")
    p.add_argument("--period", type=float, default=1.0, help="seconds between plain lines (default 1)")
    p.add_argument("--duration", type=float, default=None, metavar="S", help="stop after S seconds (plain mode)")
    add_foxglove_args(p)
    add_sensor_args(p)
    p.set_defaults(func=cmd_monitor)
