"""The reference robots: every robot file in protocol/robots/, read by the robot-file reader
(protocol.robotfile) as a user's file is, plus what makes a file a reference robot (its name is
its file's, it names its firmware example, it runs on a board with pins, it gives the emulator its
motor and body: the physics users' files without them borrow)."""

from __future__ import annotations

from pathlib import Path

from protocol.generator.loader import SpecError
from protocol.robotfile import RobotFile, parse
from protocol.robotfile.firmware import name_problem

BOARDS = ("uno", "mega2560")
"""Boards a reference robot may use: the firmware examples build for these."""


def _problem(robot: RobotFile, stem: str) -> tuple[str, str]:
    """(key, what is wrong) of a checked file that cannot be a reference robot; ("", "") if none."""
    if robot.name != stem:
        return "name", f"= {robot.name!r}: a reference robot is named as its file ({stem!r})"
    if not robot.example:
        return "firmware.example", "missing: a reference robot names its firmware example (a sketch folder)"
    if name_problem(robot.example):
        return "firmware.example", name_problem(robot.example)
    if robot.board not in BOARDS:
        return "board", f"= {robot.board!r}: a reference robot runs on one of {', '.join(BOARDS)}"
    for part in ("motor", "body"):
        if getattr(robot.emulator, part) is None:
            return f"emulator.{part}", f"missing: a reference robot gives its physics ([emulator.{part}])"
    return "", ""


def read(path: Path, rel: str) -> RobotFile:
    """The reference robot in the file at `path` (`rel`: how errors and outputs name it)."""
    robot, problems = parse(path.read_text(encoding="utf-8"), rel)
    if robot is None:
        raise SpecError(rel, "", f"{len(problems)} problem(s):\n" + "\n".join(map(str, problems)))
    key, problem = _problem(robot, path.stem)
    if problem:
        raise SpecError(rel, key, problem)
    return robot


def load(folder: Path, root: Path) -> tuple[RobotFile, ...]:
    """Every reference robot in `folder`, by file name; SpecError names the file, the key and the
    problem (a file's problems, a name or example two robots share)."""
    robots = []
    for path in sorted(folder.glob("*.toml")):
        robots.append(read(path, path.resolve().relative_to(root.resolve()).as_posix()))
    for attr in ("name", "example"):
        seen = [getattr(r, attr) for r in robots]
        dup = sorted({x for x in seen if seen.count(x) > 1})
        if dup:
            owners = ", ".join(r.path for r in robots if getattr(r, attr) in dup)
            raise SpecError(owners, attr, f"{', '.join(dup)} is used by more than one reference robot")
    if not robots:
        raise SpecError(folder.as_posix(), "", "no reference robot file (<name>.toml)")
    return tuple(robots)
