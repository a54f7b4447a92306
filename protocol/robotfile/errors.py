"""What is wrong with a robot file: each problem names the file, the key, its line, the value and
what is allowed; all of a file's problems are collected before one error is raised."""

from __future__ import annotations

from dataclasses import dataclass

from protocol.errors import RoverLinkError

_UNSET = object()


@dataclass(frozen=True)
class Problem:
    path: str
    key: str
    """Dotted key (drive.motors[0].pwm); empty for the file as a whole."""
    line: int | None
    message: str
    """What is wrong and what is allowed (the value included)."""

    def __str__(self) -> str:
        where = f"{self.path}:{self.line}" if self.line is not None else self.path
        return f"{where}: {self.key}: {self.message}" if self.key else f"{where}: {self.message}"


class RobotFileError(RoverLinkError, ValueError):
    """A robot file cannot be used; `problems` lists every reason, one per line in the message."""

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = tuple(problems)
        path = problems[0].path if problems else "robot file"
        count = f"{len(problems)} problem{'s' if len(problems) != 1 else ''}"
        super().__init__(f"{path}: {count}\n" + "\n".join(str(p) for p in problems))
