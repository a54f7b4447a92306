"""The `roverlink` command line: one subcommand per module of roverlink/commands/."""

from __future__ import annotations

import argparse
import logging
import os
import sys
from collections.abc import Sequence

from host_sdk.extras import MissingDependencyError
from host_sdk.robot.file_check import MISMATCH_LOGGER
from roverlink import __version__, say
from roverlink.commands import COMMANDS
from roverlink.interactive import take_url


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="roverlink", description="RoverLink host tools.")
    parser.add_argument("--version", action="version", version=f"roverlink {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for command in COMMANDS:
        command.add_parser(sub)
    return parser


def _parse(argv: Sequence[str] | None) -> argparse.Namespace:
    """The arguments; one the command does not take is reported by the command's own parser
    (`roverlink COMMAND: error: ...`, with its usage), as every other error of the command is."""
    parser = build_parser()
    args, unknown = parser.parse_known_args(argv)
    if unknown:
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        command: argparse.ArgumentParser = sub.choices[args.command]
        # A command module may say where such arguments belong (`unknown_hint(unknown)`).
        module = next(m for m in COMMANDS if m.__name__.rsplit(".", 1)[-1] == args.command)
        hint = getattr(module, "unknown_hint", lambda _: "")(unknown)
        command.error(f"unrecognized arguments: {' '.join(unknown)}{hint}")
    return args


def main(argv: Sequence[str] | None = None) -> int:
    args = _parse(argv)
    action = getattr(args, "action", None) or getattr(args, "firmware_command", None)
    say.running(f"roverlink {args.command}" + (f" {action}" if action else ""))
    wrong = take_url(args)
    if wrong is not None:  # as argparse reports a usage error
        say.error(f"error: {wrong}")
        return 2
    # The commands print each difference from --robot FILE themselves (`warning:` lines; the ROS 2
    # bridge hands the logger to the ROS log): unhandled, the SDK's line would reach stderr twice.
    quiet = logging.getLogger(MISMATCH_LOGGER)
    quiet.propagate = False
    if not quiet.handlers:
        quiet.addHandler(logging.NullHandler())
    try:
        result: int = args.func(args)
    except MissingDependencyError as exc:
        # An extra the command needs is not installed: one line naming it, not a traceback.
        say.error(exc)
        return 1
    except BrokenPipeError:
        # The reader went away (`roverlink info PTY | head`): stop quietly, as other tools do; the
        # interpreter's own flush at exit would otherwise fail again on the closed pipe.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141  # 128 + SIGPIPE, what a shell reports for a command a pipe stopped
    return result


if __name__ == "__main__":
    sys.exit(main())
