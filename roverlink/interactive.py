"""What the interactive commands share: connection arguments, questions, a progress line.

Questions go through a `Prompter` so a test (or the emulator playing the user) can answer them;
`ConsolePrompter` asks on the terminal. Progress is a live line on a terminal and a line every few
seconds otherwise, so logs of a long run stay readable.
"""

from __future__ import annotations

import argparse
import socket
import sys
import time
from typing import TYPE_CHECKING, Protocol, TextIO

from host_sdk import PROFILES, Robot, RobotDescription
from host_sdk.calibration import CalibrationFile
from host_sdk.console.access import is_loopback
from roverlink import argtypes
from roverlink.argtypes import kinematics_arg
from roverlink.emulated import emu_robot

if TYPE_CHECKING:
    from host_sdk.recording import Recorder


URL_HELP = "the board: a serial port (/dev/ttyACM0), socket://host:port, or an emu:// URL with its sensors"


def add_url_args(
    p: argparse._ActionsContainer,
    *,
    without: str | None = None,
    positional: bool = True,
    baud: int | None = 115200,
    baud_help: str = "115200",
    port_alias: bool = False,
) -> None:
    """The board's URL and line speed, as every robot command takes them: the URL as the first
    argument (`positional`) or as `--url URL` (`--port URL` too with `port_alias`), and `--baud`. `without`: what the
    command does when no URL is given (None: one is required; `take_url` checks)."""
    default = f" (default: {without})" if without is not None else ""
    names = ("--url", "--port") if port_alias else ("--url",)
    if positional:
        p.add_argument("url", nargs="?", default=None, help=URL_HELP + default)
        p.add_argument(*names, dest="url_option", metavar="URL", default=None, help="the same, as an option")
    else:
        p.add_argument(*names, dest="url", metavar="URL", default=None, help=URL_HELP + default)
    p.add_argument(
        "--baud", type=argtypes.BAUD, default=baud, help=f"the board's line speed in bit/s (default {baud_help})"
    )
    p.set_defaults(url_optional=without is not None)


def add_robot_args(p: argparse.ArgumentParser, *, timeout: float = 5.0) -> None:
    """The URL and the connection options every command that needs a board takes (`add_url_args`)."""
    add_url_args(p)
    add_profile_args(p, help_text="reference robot, for its kinematics (default: the one the firmware names)")
    p.add_argument(
        "--timeout",
        type=argtypes.number(0, 600, "s", lo_open=True),
        default=timeout,
        help=f"how long to wait for the board, in s (default {timeout:g}; an Arduino's bootloader takes ~2)",
    )
    add_kinematics_arg(p)


def take_url(args: argparse.Namespace) -> str | None:
    """Put `--url URL` where the commands read the URL (args.url); None, or what is wrong (given
    twice, or not given to a command that needs one)."""
    if not hasattr(args, "url_option"):
        return None
    if args.url is not None and args.url_option is not None:
        return f"the URL given twice ({args.url} and --url {args.url_option}): give it once"
    args.url = args.url if args.url is not None else args.url_option
    if args.url is None and not getattr(args, "url_optional", False):
        return "give the board's URL (first argument or --url), e.g. /dev/ttyACM0"
    return None


def robot_named(args: argparse.Namespace, default: str) -> str | RobotDescription:
    """The robot a command drives: --robot FILE, else --profile, else the reference robot an
    emu://NAME URL names, else `default`."""
    if getattr(args, "robot", None) is not None:
        robot: str | RobotDescription = args.robot
        return robot
    if getattr(args, "profile", None) is not None:
        return str(args.profile)
    return emu_robot(getattr(args, "url", None)) or default


def add_profile_args(p: argparse.ArgumentParser, *, help_text: str, default: str | None = None) -> None:
    """--profile NAME or --robot FILE (one of them), and --allow-mismatch."""
    which = p.add_mutually_exclusive_group()
    which.add_argument("--profile", choices=sorted(PROFILES), default=default, help=help_text)
    _add_robot_file_args(which, p)


def _add_robot_file_args(which: argparse._ActionsContainer, p: argparse._ActionsContainer) -> None:
    """--robot FILE (in `which`: a group that excludes --profile) and --allow-mismatch."""
    which.add_argument(
        "--robot",
        type=argtypes.robot_file_arg,
        default=None,
        metavar="FILE",
        help="your robot file (docs/robot-file.md): its kinematics, limits and gains; the board is checked against it",
    )
    p.add_argument(
        "--allow-mismatch",
        action="store_true",
        help="connect even if the board differs from --robot FILE (the differences are warned about)",
    )


def add_kinematics_arg(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--kinematics",
        type=kinematics_arg,
        default=None,
        metavar="FILE",
        help="calibration file from `roverlink calibrate -o` (the track width the board does not store)",
    )


def connect(args: argparse.Namespace, **options: object) -> Robot:
    """Robot.connect with the command's connection arguments (and --kinematics FILE's kinematics)."""
    cal: CalibrationFile | None = getattr(args, "kinematics", None)
    kinematics = cal.kinematics if cal is not None else None
    robot = Robot.connect(
        args.url,
        baud=args.baud,
        profile=args.profile,
        timeout_s=args.timeout,
        kinematics=kinematics,
        robot=getattr(args, "robot", None),
        allow_mismatch=getattr(args, "allow_mismatch", False),
        **options,  # type: ignore[arg-type]
    )
    warn_mismatches(robot)
    if cal is not None:
        for line in calibration_mismatch(cal, robot):
            print(f"note: {line}", file=sys.stderr)
    return robot


def warn_mismatches(robot: Robot) -> None:
    """One warning line per difference between the board and --robot FILE (--allow-mismatch), and
    a note when the file changed the board's gains."""
    for mismatch in robot.mismatches:
        print(f"warning: {mismatch} (--allow-mismatch)", file=sys.stderr)
    if robot.gains_notice is not None:
        print(f"note: {robot.gains_notice}", file=sys.stderr)


def calibration_mismatch(cal: CalibrationFile, robot: Robot) -> list[str]:
    """Where a calibration file disagrees with the robot it is used on: another robot, or a board
    configuration changed since (its wheel diameter or encoder counts are not the file's)."""
    out = []
    name = robot.identity.robot_name
    if cal.robot and name and cal.robot != name:
        out.append(f"{cal.path} was calibrated on {cal.robot}; this robot is {name}")
    config = robot.config
    kin = cal.kinematics
    board = {"wheel_radius_m": config.wheel_diameter_um / 2e6, "counts_per_rev": config.encoder_cpr}
    for field, value in board.items():
        mine = getattr(kin, field)
        if abs(mine - value) > 1e-3 * abs(value):
            out.append(f"{cal.path} has {field} {mine:g}, the board {value:g}: its configuration changed since")
    return out


class Prompter(Protocol):
    """Asks the user; `say` tells them something."""

    def say(self, text: str) -> None: ...

    def confirm(self, question: str, default: bool = False) -> bool: ...

    def number(self, question: str, default: float | None = None) -> float: ...


class ConsolePrompter:
    """Asks on stdin/stdout. `assume_yes` answers every yes/no question with yes (`--yes`)."""

    def __init__(self, assume_yes: bool = False, out: TextIO | None = None, inp: TextIO | None = None) -> None:
        self.assume_yes = assume_yes
        self.out = out or sys.stdout
        self.inp = inp or sys.stdin

    def say(self, text: str) -> None:
        print(text, file=self.out, flush=True)

    def _read(self, prompt: str) -> str:
        print(prompt, end="", file=self.out, flush=True)
        line = self.inp.readline()
        if not line:
            raise EOFError("no answer: standard input is closed (pass --yes to skip the questions that allow it)")
        return line.strip()

    def confirm(self, question: str, default: bool = False) -> bool:
        if self.assume_yes:
            self.say(f"{question} [yes: --yes]")
            return True
        hint = "[Y/n]" if default else "[y/N]"
        while True:
            answer = self._read(f"{question} {hint} ").lower()
            if not answer:
                return default
            if answer in ("y", "yes"):
                return True
            if answer in ("n", "no"):
                return False
            self.say("please answer y or n")

    def number(self, question: str, default: float | None = None) -> float:
        hint = f" [{default:g}]" if default is not None else ""
        while True:
            answer = self._read(f"{question}{hint}: ")
            if not answer and default is not None:
                return default
            try:
                return float(answer)
            except ValueError:
                self.say(f"{answer!r} is not a number")


class Progress:
    """A live status line: rewritten in place on a terminal, printed every `every_s` otherwise."""

    def __init__(self, out: TextIO | None = None, every_s: float = 5.0) -> None:
        self.out = out or sys.stderr
        self.tty = self.out.isatty()
        self.every_s = every_s
        self._last = -1e9
        self._width = 0

    def update(self, text: str) -> None:
        if self.tty:
            pad = max(0, self._width - len(text))
            print("\r" + text + " " * pad, end="", file=self.out, flush=True)
            self._width = len(text)
            return
        now = time.monotonic()
        if now - self._last >= self.every_s:
            self._last = now
            print(text, file=self.out, flush=True)

    def done(self) -> None:
        if self.tty and self._width:
            print(file=self.out, flush=True)
            self._width = 0


def bar(fraction: float, width: int = 20) -> str:
    """A text progress bar: [#########-----------]."""
    filled = max(0, min(width, round(fraction * width)))
    return "[" + "#" * filled + "-" * (width - filled) + "]"


LAYOUT_HINT = "docs/foxglove-layout.json"


def announce_live_view(recorder: Recorder, out: TextIO | None = None) -> None:
    """Print the live view's address (and, off loopback, that anyone on the network can watch it)."""
    sink, stream = recorder.sink, out or sys.stderr
    url = sink.url
    if url is None:
        return
    print(
        f"live view: {url} (Foxglove: Open connection > Foxglove WebSocket; layout {LAYOUT_HINT})",
        file=stream,
        flush=True,
    )
    if not is_loopback(sink.host):
        if sink.host in ("0.0.0.0", "::"):
            print(f"  from another machine: ws://{socket.gethostname()}.local:{sink.port}", file=stream, flush=True)
        print(
            "  warning: the Foxglove server has no access control: anyone who can reach this address can "
            "watch (it accepts no commands); an SSH tunnel keeps it private (docs/tools.md)",
            file=stream,
            flush=True,
        )
