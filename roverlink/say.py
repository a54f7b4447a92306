"""How a command says it failed: one line on stderr, `roverlink COMMAND: what went wrong`.

The rule of every command (argparse's usage errors read the same way: `roverlink COMMAND: error:
...`), so a script or a user can tell which command of a pipeline failed. `roverlink.cli` names
the command that runs (`roverlink robot show`, `roverlink firmware build`); a command's own
console script (`roverlink-ros2`) names itself. Warnings and notes keep their `warning:` and
`note:` lines; what a running command tells its user (where to open the console) goes through
`notice`, in the same form.
"""

from __future__ import annotations

import sys

_command = ["roverlink"]


def running(name: str) -> None:
    """The command that runs now, as its errors name it (e.g. "roverlink decode")."""
    _command[0] = name


def prefix() -> str:
    return _command[0]


def error(text: object) -> None:
    """`text` (a message or an exception) on stderr after the command's name."""
    print(f"{_command[0]}: {text}", file=sys.stderr)


def notice(text: object) -> None:
    """What the running command tells its user on stderr (not an error), in the same form."""
    print(f"{_command[0]}: {text}", file=sys.stderr, flush=True)
