"""`roverlink info URL`: a board's identity, configuration and PID gains."""

from __future__ import annotations

import argparse
import dataclasses

from host_sdk import RoverLinkError
from host_sdk.extras import MissingDependencyError
from protocol.generated.enums import Capability
from roverlink import say
from roverlink.interactive import add_robot_args, connect


def capabilities_text(capabilities: Capability) -> str:
    """The capability bits by name and their value: `DIFF_DRIVE|ENCODERS: 5`."""
    return f"{capabilities!r}".removeprefix("<Capability.").removesuffix(">")


def cmd_info(args: argparse.Namespace) -> int:
    """Handshake with a board and print its identity, configuration and PID gains."""
    try:
        with connect(args) as robot:
            ident = robot.identity
            s = robot.stats
            print(f"{robot.url}: {ident.robot_name or '(unnamed)'} firmware {ident.version} on {ident.board.name}")
            print(f"  protocol v{ident.protocol_version}, spec hash 0x{ident.spec_hash:08X}")
            print(f"  capabilities  {capabilities_text(ident.capabilities)}")
            print(f"  boot_id 0x{ident.boot_id:08X}, up {ident.uptime_ms / 1000:.1f} s")
            print(
                f"  session: watchdog {ident.watchdog_ms} ms, {ident.feedback_mode.name.lower()} feedback "
                f"at {ident.feedback_hz} Hz"
            )
            if s.connect_time_s is not None:
                print(f"  ready {s.connect_time_s * 1000:.1f} ms after the first HELLO")
            print("configuration:")
            for name, value in robot.config.fields().items():
                shown = value.name if hasattr(value, "name") else value
                print(f"  {name:<22} {shown}")
            wheels = 2 if ident.capabilities & ident.capabilities.DIFF_DRIVE else 1
            for wheel in range(wheels):
                g = robot.pid(wheel)
                print(f"PID wheel {wheel}: kp {g.kp:g}, ki {g.ki:g}, kd {g.kd:g}, kf {g.kf:g}, ks {g.ks:g}")
            kin = robot.kinematics
            if kin is not None:
                cal, described = args.kinematics, getattr(args, "robot", None)
                if cal is not None:
                    where = f"from {cal.path}"
                elif described is not None:
                    where = f"from {getattr(described, 'path', described)}"
                else:
                    where = "from the profile and the board"
                values = ", ".join(f"{f.name} {getattr(kin, f.name):g}" for f in dataclasses.fields(kin))
                print(f"kinematics {type(kin).__name__} ({where}): {values}")
            rtt = robot.stats.rtt
            if rtt is not None:
                print(f"round trip {rtt.min_s * 1000:.2f} ms")
    except MissingDependencyError:
        raise  # cli.main names the extra
    except RoverLinkError as exc:
        say.error(f"{exc}")
        return 1
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("info", help=cmd_info.__doc__, description=cmd_info.__doc__)
    add_robot_args(p)
    p.set_defaults(func=cmd_info)
