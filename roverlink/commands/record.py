"""`roverlink record URL -o FILE.mcap [--duration S] [--foxglove]`: record a robot and its sensors
to MCAP, and optionally serve the same messages live to Foxglove (on 127.0.0.1 unless --foxglove-host
says otherwise).

The sensors are those an `emu://` URL attached, or those named with --lidar/--imu/--camera
(roverlink.sensors): a lidar's scans as foxglove.LaserScan, the camera's frames as
foxglove.CompressedImage, the IMU's samples as roverlink.Imu.

Read-only, like `monitor`: it opens a session (which leaves the board disarmed) and never arms
or commands; drive the robot from a program that records itself (`Recorder.attach` in
host_sdk.recording, or `follow --foxglove`) to record a drive.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from host_sdk import Robot, RoverLinkError
from host_sdk.extras import MissingDependencyError
from host_sdk.recording import Recorder, RecordingSummary
from roverlink import say
from roverlink.interactive import LAYOUT_HINT, Progress, add_robot_args, announce_live_view, bar, connect
from roverlink.sensors import add_sensor_args, choose_sensors, open_sensors

POLL_S = 0.05


def add_foxglove_args(p: argparse.ArgumentParser, *, serve_flag: str | None = "--foxglove") -> None:
    """--foxglove (`serve_flag`), --foxglove-host and --foxglove-port, shared by record, monitor and follow."""
    if serve_flag is not None:
        p.add_argument(serve_flag, action="store_true", help="serve a live Foxglove WebSocket view while running")
    add_foxglove_address_args(p)


def add_foxglove_address_args(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--foxglove-host",
        default="127.0.0.1",
        metavar="HOST",
        help="address the live view listens on (default 127.0.0.1: this machine only; 0.0.0.0: every "
        "network, with no access control: docs/tools.md)",
    )
    p.add_argument(
        "--foxglove-port", type=int, default=8765, metavar="PORT", help="port of the live view (default 8765; 0: any)"
    )


def record(robot: Robot, recorder: Recorder, duration_s: float | None, progress: Progress) -> RecordingSummary:
    """Record until `duration_s` of the robot's clock has passed (None: until Ctrl-C)."""
    start = robot.now()
    try:
        while True:
            elapsed = robot.now() - start
            if duration_s is not None and elapsed >= duration_s:
                break
            # 50 ms steps: an emulated camera on the virtual clock keeps only 4 frames between polls.
            step = POLL_S if duration_s is None else min(POLL_S, max(0.001, duration_s - elapsed))
            robot.sleep(step)
            recorder.poll()
            total = sum(recorder.sink.counts.values())
            shown = f"{bar(elapsed / duration_s)} " if duration_s else ""
            progress.update(f"recording {shown}{elapsed:6.1f} s  {total} messages")
    except KeyboardInterrupt:
        pass
    finally:
        progress.done()
    return recorder.close()


def cmd_record(args: argparse.Namespace) -> int:
    """Record feedback, odometry, wheel series, link statistics, LOG lines and the sensors to MCAP."""
    path = Path(args.output)
    if path.suffix != ".mcap":
        say.error(f"-o {path}: the file name should end in .mcap")
        return 2
    if path.exists() and not args.force:
        say.error(f"{path} exists (pass --force to overwrite)")
        return 1
    if args.duration is not None and args.duration <= 0:
        say.error(f"--duration {args.duration:g}: a number of seconds > 0")
        return 2
    try:
        with connect(args, feedback_hz=args.rate) as robot:
            choice = choose_sensors(args, robot)
            with open_sensors(choice) as sensors:
                recorder = Recorder.attach(
                    robot,
                    mcap_path=path,
                    overwrite=args.force,
                    serve=args.foxglove,
                    host=args.foxglove_host,
                    port=args.foxglove_port,
                    sensors=sensors,
                )
                announce_live_view(recorder)
                name = robot.identity.robot_name or "robot"
                print(f"recording {name} on {robot.url} to {path}" + ("" if args.duration else " (Ctrl-C stops)"))
                for line in choice.lines():
                    print(f"  with the {line}")
                summary = record(robot, recorder, args.duration, Progress())
    except MissingDependencyError:
        raise  # cli.main names the extra
    except (RoverLinkError, OSError) as exc:
        say.error(f"{exc}")
        return 1
    print("\n".join(summary.lines()))
    print(f"open {path} in Foxglove with the layout {LAYOUT_HINT}")
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("record", help=cmd_record.__doc__, description=__doc__.split("\n\n")[0])
    add_robot_args(p)
    p.add_argument("-o", "--output", required=True, metavar="FILE.mcap", help="MCAP file to write")
    p.add_argument("--duration", type=float, default=None, metavar="S", help="stop after S seconds (default: Ctrl-C)")
    p.add_argument("--rate", type=int, default=50, metavar="HZ", help="feedback rate asked of the board (default 50)")
    p.add_argument("--force", action="store_true", help="overwrite FILE.mcap if it exists")
    add_foxglove_args(p)
    add_sensor_args(p)
    p.set_defaults(func=cmd_record)
