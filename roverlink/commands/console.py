"""`roverlink console`: the robot in a browser (camera with the tracked box, scan, pose, status;
draw the target, follow, drive, arm, stop), served by the robot program (docs/console.md).

On the emulator (wall clock, so a person can drive it):

    roverlink console --world random:3 --profile picar

On a robot, opened from a laptop on the same network (a token is made and printed in the URL):

    roverlink console --url /dev/ttyACM0 --profile picar --lidar /dev/ttyUSB0 --camera picamera2 --host 0.0.0.0

Runs until Ctrl-C (or --duration seconds).
"""

from __future__ import annotations

import argparse

from emulator.sensors.camera import LOOKS
from host_sdk import RoverLinkError
from host_sdk.console import Access
from host_sdk.errors import CommandRangeError, TransportError
from host_sdk.extras import MissingDependencyError, require
from protocol.generated.constants import WATCHDOG_MAX_MS, WATCHDOG_MIN_MS
from roverlink import say
from roverlink.argtypes import number, positive
from roverlink.console_app import ConsoleSettings, start_emulated, start_robot
from roverlink.follow.app import robot_ports
from roverlink.follow.emulated import watchdog_for
from roverlink.interactive import add_profile_args, add_url_args, robot_named
from roverlink.sensors.options import add_sensor_args


def _port(text: str) -> int:
    if not text.isdigit() or not 0 <= int(text) <= 65535:
        raise argparse.ArgumentTypeError(f"{text} is not allowed: a TCP port, 0 to 65535 (0: any free one)")
    return int(text)


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser(
        "console",
        help="the robot in a browser: camera, scan, pose, status; draw the target, follow, drive, stop",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_profile_args(p, help_text="reference robot (default: the one an emu://NAME URL names, else picar)")
    p.add_argument(
        "--host",
        default="127.0.0.1",
        help="address to listen on (default 127.0.0.1: this machine only; 0.0.0.0: every network, with a token)",
    )
    p.add_argument("--port", type=_port, default=8080, help="TCP port (default 8080; 0: any free one)")
    p.add_argument("--token", help="the token clients must give (default: a random one off loopback)")
    p.add_argument("--duration", type=positive, help="stop after this many seconds (default: at Ctrl-C)")
    p.add_argument("--max-speed", type=positive, default=0.45, help="top speed, m/s (default 0.45)")
    p.add_argument("--follow-gap", type=positive, help="gap to keep to the target, m (default 0.5; Ackermann 0.9)")
    p.add_argument("--target-height", type=positive, metavar="M", help="the target's height (gives its range)")
    p.add_argument(
        "--autonomous",
        action="store_true",
        help="keep following with no browser open (by default following ends when the driving "
        "browser's keep-alive lapses: tab closed, frozen or hidden, Wi-Fi gone); said at the "
        "start and on the page",
    )
    e = p.add_argument_group("on the emulator")
    e.add_argument("--world", metavar="FILE|random:SEED", help="a scenario file or random:SEED (default random:SEED)")
    e.add_argument("--seed", type=int, default=0, help="the emulator's random seed (default 0)")
    e.add_argument("--camera-fps", type=positive, default=15.0, help="emulated camera frame rate (default 15)")
    e.add_argument("--camera-look", choices=LOOKS, default="plain", help="emulated camera: plain or photo")
    e.add_argument("--no-imu", action="store_true", help="no IMU: wheel odometry alone")
    r = p.add_argument_group("on a robot")
    add_url_args(r, without="an emulated robot")
    r.add_argument(
        "--watchdog",
        type=number(WATCHDOG_MIN_MS / 1000, WATCHDOG_MAX_MS / 1000, "s"),
        metavar="S",
        help="the board's watchdog, which is also how long a command from the page lives (default the "
        "firmware's, 0.25 s; longer for a host too busy to renew commands in time)",
    )
    add_sensor_args(p, off=None)
    p.set_defaults(func=cmd_console)


def cmd_console(args: argparse.Namespace) -> int:
    require("aiohttp", "console", "roverlink console")
    try:
        Access.for_host(args.host, args.token)  # checked before anything starts
    except CommandRangeError as exc:
        say.error(f"--{exc}")
        return 2
    settings = ConsoleSettings(
        args.host,
        args.port,
        args.token,
        args.max_speed,
        args.target_height,
        args.follow_gap,
        args.autonomous,
        args.watchdog,
    )
    which = robot_named(args, "picar")
    try:
        if args.url is None:
            world = args.world or f"random:{args.seed}"
            # The emulator shares this process on the wall clock: a 1 s watchdog keeps a busy machine
            # from failing it safe every few seconds (docs/console.md, "On the emulator").
            run = start_emulated(
                which,
                world,
                settings,
                seed=args.seed,
                camera_fps=args.camera_fps,
                imu=not args.no_imu,
                camera_look=args.camera_look,
                watchdog_s=watchdog_for(None, args.watchdog),
            )
        else:
            ports = robot_ports(args)
            try:
                ports.check(which)
            except RoverLinkError as exc:
                say.error(exc)
                return 2
            run = start_robot(ports, which, settings)
    except MissingDependencyError:
        raise
    except TransportError as exc:
        hint = " (--host, --port)" if "console cannot listen" in str(exc) else ""
        say.error(f"{exc}{hint}")
        return 1
    except (RoverLinkError, ValueError, OSError, RuntimeError) as exc:
        say.error(f"{exc}")
        return 1
    say.notice("open " + "  or  ".join(run.console.urls))
    if args.autonomous:
        say.notice("--autonomous: following goes on with no browser open; STOP on the page or Ctrl-C here stops it")
    try:
        run.run(args.duration)
    except KeyboardInterrupt:
        pass
    except (RoverLinkError, OSError, RuntimeError) as exc:
        say.error(f"{exc}")
        return 1
    finally:
        run.close()
    return 0
