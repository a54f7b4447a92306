"""`roverlink follow`: follow a target with the camera while avoiding obstacles with the lidar.

On the emulator (virtual clock, as fast as the CPU allows):

    roverlink follow --world random:3 --profile picar --duration 60 --json

Your own robot (docs/robot-file.md): `--robot my.toml` in place of --profile; on the emulator the
emulated robot is the file's, on a robot the board is checked against it; the pilot's geometry (footprint,
camera, lidar mount, steering) and the lidar model are the file's.

On a robot (the board, the lidar, the camera and optionally the IMU):

    roverlink follow --url /dev/ttyACM0 --profile picar --lidar /dev/ttyUSB0 \\
        --camera picamera2 --template target.png --target-height 0.3

or follow a person (or a face) the camera sees, picked by a detector and found again by it when lost:

    roverlink follow --url /dev/ttyACM0 --profile picar --lidar /dev/ttyUSB0 --camera picamera2 --target person

Progress goes to stderr once a second; with --json the metrics are printed on stdout at the end
(duration, collisions (emulator), the share of the time the target was in view, following error,
reacquisition times, distance driven). `--pilot picar-2018` runs the PiCar team's published approach
instead of RoverLink's, for comparison (benchmarks/follow.py runs both on many worlds).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TextIO

from emulator.sensors.camera import LOOKS
from host_sdk import RoverLinkError
from host_sdk.errors import CommandRangeError
from host_sdk.extras import MissingDependencyError, require
from host_sdk.perception.detectors import KINDS
from host_sdk.perception.template import read_template
from roverlink import say
from roverlink.argtypes import positive
from roverlink.commands.record import add_foxglove_address_args
from roverlink.follow.app import PILOTS, FollowSettings, RecordTo, robot_ports, run_emulated, run_robot
from roverlink.follow.metrics import FollowMetrics
from roverlink.follow.run import Progress
from roverlink.interactive import add_profile_args, add_url_args, robot_named
from roverlink.sensors.options import add_sensor_args


def _box(text: str) -> tuple[float, float, float, float]:
    parts = text.split(",")
    try:
        x, y, w, h = (float(v) for v in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not allowed: X,Y,W,H in pixels, e.g. 140,90,40,60") from None
    if w <= 0 or h <= 0 or x < 0 or y < 0:
        raise argparse.ArgumentTypeError(f"{text} is not allowed: X, Y >= 0 and W, H > 0 pixels")
    return x, y, w, h


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser(
        "follow",
        help="follow a target with the camera while avoiding obstacles with the lidar",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_profile_args(p, help_text="reference robot (default: the one an emu://NAME URL names, else picar)")
    p.add_argument("--duration", type=positive, default=60.0, help="seconds to run (default 60)")
    p.add_argument("--pilot", choices=PILOTS, default="roverlink", help="whose behaviour drives (default roverlink)")
    p.add_argument("--follow-gap", type=positive, help="gap to keep to the target, m (default 0.5; Ackermann 0.9)")
    p.add_argument("--max-speed", type=positive, default=0.45, help="top speed, m/s (default 0.45)")
    p.add_argument(
        "--rearm",
        action="store_true",
        help="arm again by itself after a failsafe or a board reset and go on following (off by "
        "default: the robot then stays disarmed; said at the start when on)",
    )
    p.add_argument("--json", action="store_true", help="print the metrics as JSON on stdout at the end")
    p.add_argument("--quiet", action="store_true", help="no progress lines on stderr")
    p.add_argument(
        "--foxglove", metavar="FILE.mcap", type=Path, help="record the run (robot, scan, tracked camera, behaviour)"
    )
    p.add_argument("--foxglove-live", action="store_true", help="serve the run to Foxglove live (its URL is printed)")
    add_foxglove_address_args(p)
    e = p.add_argument_group("on the emulator")
    e.add_argument("--world", metavar="FILE|random:SEED", help="a scenario file or random:SEED (selects the emulator)")
    e.add_argument("--seed", type=int, default=0, help="the emulator's random seed (default 0)")
    e.add_argument("--camera-fps", type=positive, default=15.0, help="emulated camera frame rate (default 15)")
    e.add_argument(
        "--camera-look",
        choices=LOOKS,
        default="plain",
        help="emulated camera: plain (flat colours, default) or photo (docs/emulator.md)",
    )
    e.add_argument("--no-imu", action="store_true", help="no IMU: wheel odometry alone")
    r = p.add_argument_group("on a robot")
    add_url_args(r, without="an emulated robot")
    add_sensor_args(p, off=None)
    r.add_argument(
        "--template",
        type=Path,
        metavar="IMAGE",
        help="an image of the target (a PNG with its background transparent: the object's pixels only)",
    )
    r.add_argument(
        "--select",
        type=_box,
        metavar="X,Y,W,H",
        help="the target's box in the first frame (or draw it live: roverlink console)",
    )
    r.add_argument("--target", choices=KINDS, help="follow a detected person or face (in place of --template/--select)")
    r.add_argument(
        "--target-height",
        type=positive,
        metavar="M",
        help="the target's height (gives its range; --target: default 1.7 person, 0.16 face)",
    )
    p.set_defaults(func=cmd_follow)


def _progress(out: TextIO, rearm: bool) -> Callable[[Progress], None]:
    def show(p: Progress) -> None:
        gap = f"gap {p.gap_m:4.2f} m" if p.gap_m is not None else "gap   -   "
        seen = "target seen" if p.tracked else "target lost"
        hits = f"  collisions {p.metrics.collisions}" if p.metrics.ground_truth else ""
        trouble = p.trouble
        if trouble is not None and trouble.startswith("failsafe ") and not rearm:
            trouble = "disarmed after the failsafe"  # said in full once, on the failsafe's line
        line = f"{p.t_s:6.1f} s  {p.mode:8s} {gap}  {seen}{hits}"
        if p.failsafe is None:
            print(line + (f"  ({trouble})" if trouble else ""), file=out, flush=True)
        else:  # the failsafe met, in words, on a line of its own, and what happens now
            print(line, file=out, flush=True)
            then = (
                "armed again (--rearm)" if rearm else "disarmed for the rest of the run: run it again, or with --rearm"
            )
            print(f"         failsafe {p.failsafe}; {then}", file=out, flush=True)

    return show


def _summary(m: FollowMetrics) -> str:
    view = "-" if m.in_view_fraction is None else f"{100 * m.in_view_fraction:.1f} %"
    tracked = "-" if m.tracked_fraction is None else f"{100 * m.tracked_fraction:.1f} %"
    err = "-"
    if m.follow_error_mean_m is not None:
        err = f"{m.follow_error_mean_m:.2f} m mean, {m.follow_error_max_m:.2f} m max"
    reacq = ", ".join(f"{v:.1f} s" for v in m.reacquisitions_s) or "none"
    first = "never" if m.first_sight_s is None else f"{m.first_sight_s:.1f} s"
    hits = "collisions unknown" if m.collisions is None else f"collisions {m.collisions}"
    return (
        f"{m.pilot} on {m.profile} ({m.world or m.url}), {m.duration_s:.1f} s: {hits}, "
        f"first sight {first}, target in view {view} (tracked {tracked}), following error {err}, "
        f"reacquisitions {reacq}, {m.distance_m:.1f} m driven"
    )


def cmd_follow(args: argparse.Namespace) -> int:
    """Follow a target with the camera while avoiding obstacles with the lidar."""
    settings = FollowSettings(
        args.follow_gap, args.max_speed, args.target_height, args.duration, args.target, args.rearm
    )
    if args.rearm:
        say.notice(
            "--rearm: the robot is armed again by itself after a failsafe or a board reset, and goes on following"
        )
    record = None
    if args.foxglove or args.foxglove_live:
        record = RecordTo(args.foxglove, args.foxglove_live, args.foxglove_host, args.foxglove_port)
    progress = None if args.quiet else _progress(sys.stderr, args.rearm)
    run = _follow_emulated if args.url is None else _follow_robot
    try:
        metrics = run(args, settings, progress, record)
    except MissingDependencyError:
        raise  # cli.main names the extra
    except (RoverLinkError, ValueError, OSError, RuntimeError) as exc:
        say.error(f"{exc}")
        return 1
    if metrics is None:
        return 2  # refused, and said why
    if args.json:
        print(json.dumps(metrics.to_json(), indent=1))
    else:
        print(_summary(metrics))
    return 0


def _follow_emulated(
    args: argparse.Namespace,
    settings: FollowSettings,
    progress: Callable[[Progress], None] | None,
    record: RecordTo | None,
) -> FollowMetrics | None:
    """The emulated run (its own world and target); None after saying why it is refused."""
    if args.target is not None:
        say.error("--target needs a robot's camera (--url): the emulated target is a rendered cylinder, not a person")
        return None
    given = [name for name in ("select", "template") if getattr(args, name) is not None]
    if given:
        say.error(
            f"--{given[0]} is for a robot's camera (--url): on the emulator the target "
            "is the world's (roverlink console lets you draw it)"
        )
        return None
    return run_emulated(
        robot_named(args, "picar"),
        args.world or f"random:{args.seed}",
        pilot=args.pilot,
        seed=args.seed,
        camera_fps=args.camera_fps,
        imu=not args.no_imu,
        settings=settings,
        camera_look=args.camera_look,
        progress=progress,
        record=record,
    )


def _follow_robot(
    args: argparse.Namespace,
    settings: FollowSettings,
    progress: Callable[[Progress], None] | None,
    record: RecordTo | None,
) -> FollowMetrics | None:
    """A robot at --url with its sensors; None after saying why it is refused."""
    robot = robot_named(args, "picar")
    targets = sum(v is not None for v in (args.template, args.select, args.target))
    emulated = args.url.startswith("emu://")
    if emulated and args.target is not None:
        say.error("--target needs a robot's camera: the emulated target is a rendered cylinder, not a person")
        return None
    if targets > 1 or (targets == 0 and not emulated):
        say.error("on a robot give one of --template, --select, --target (an emu:// robot follows its own target)")
        return None
    template = None
    if args.template is not None:
        require("cv2", "vision", "--template")
        try:
            template = read_template(args.template)
        except CommandRangeError:
            say.error(f"cannot read the image {args.template}")
            return None
    ports = robot_ports(args)
    try:
        ports.check(robot)
    except RoverLinkError as exc:
        say.error(exc)
        return None
    return run_robot(
        ports,
        robot,
        template=template,
        select=args.select,
        pilot=args.pilot,
        settings=settings,
        progress=progress,
        record=record,
    )
