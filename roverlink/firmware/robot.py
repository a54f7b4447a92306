"""A robot file's firmware: the library example that fits its drive, with `robot_profile.h` generated
from the file (protocol.robotfile.firmware), as a sketch folder of its own.

    robot = load_robot("my.toml")                 # every problem in one RobotFileError, or the robot
    sketch = write_sketch(robot, BUILD_ROOT / ...)  # <dir>/<dir name>.ino + robot_profile.h

The library and its examples are never written: the sketch is a copy in a folder of its own (the
build directory, or the folder `roverlink firmware sketch` is given).
"""

from __future__ import annotations

import hashlib
import re
import textwrap
from pathlib import Path

from protocol.generator import wiring as rules
from protocol.generator.hardware import pico_pinout
from protocol.robotfile import Problem, RobotFile, RobotFileError, check, load
from protocol.robotfile.firmware import example_for, example_reference, examples, name_problem, profile_header
from protocol.robotfile.lines import line_of
from roverlink.firmware.boards import BUILD_ROOT, BoardSpec, FirmwareError, board_spec, example_dir
from roverlink.firmware.boards import examples as library_examples

SKETCH_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*$")
"""What the Arduino IDE accepts as a sketch (folder) name."""
_UNO_PCINT2 = frozenset(range(2, 8))  # port D; 0 and 1 are the serial port's
_MEGA_PCINT2 = frozenset(range(62, 70))  # port K: A8..A15
_NO_LIGHTS = ("DiffDriveBTS7960", "AckermannPiCar")


class _Problems:
    def __init__(self, robot: RobotFile) -> None:
        self.robot = robot
        self.text = Path(robot.path).read_text(encoding="utf-8")
        self.found: list[Problem] = []

    def add(self, section: str, path: tuple[str | int, ...], message: str) -> None:
        line = line_of(self.text, section, path) or line_of(self.text, section)
        key = ".".join(x for x in (section, *map(str, path)) if x)
        self.found.append(Problem(self.robot.path, key, line, message))


def _pins_problems(p: _Problems, example: str) -> None:
    robot = p.robot
    board = robot.board.upper()
    if example in _NO_LIGHTS and robot.wiring.led_pins:
        p.add("lights", (), f"the {example} example drives no lights: leave [lights] out")
    if example == "DiffDriveTB6612" and not robot.wiring.led_pins:
        p.add("lights", (), f"the {example} example drives four turn-signal LEDs: give their pins in [lights]")
    if len(robot.wiring.encoders) != robot.drive.channels:
        p.add("encoders", ("pins",), f"the {example} example needs encoder pins for each wheel channel")
    if example == "DiffDriveBTS7960":
        port, what = (_UNO_PCINT2, "2..7") if board == "UNO" else (_MEGA_PCINT2, "A8..A15")
        why = f"on PCINT2's port ({what}): the {example} example counts with its one vector"
    else:
        port, what = rules.BOARD_PINS[board].interrupts, ", ".join(map(str, sorted(rules.BOARD_PINS[board].interrupts)))
        why = f"on an external interrupt ({what}): the {example} example counts with attachInterrupt"
    for i, enc in enumerate(robot.wiring.encoders):
        for role, pin in enc.pins:
            if pin not in port:
                p.add("encoders", ("pins", i, role), f"= {pin}: must be {why}")
    timer1 = rules.BOARD_PINS[board].rc_timers[0][1]
    for section, rc_pin in (("esc", robot.wiring.esc_pin), ("steering", robot.wiring.servo_pin)):
        if rc_pin is not None and rc_pin not in timer1:
            pins = " or ".join(map(str, timer1))
            p.add(section, ("pin",), f"= {rc_pin}: the {example} example pulses Timer1's pins ({pins})")


def firmware_problems(robot: RobotFile) -> list[Problem]:
    """What stops a checked robot file from becoming a firmware: the board, a driver no example
    drives, the name the firmware reports, and the pins the chosen example relies on."""
    p = _Problems(robot)
    problem = name_problem(robot.name)
    if problem:
        p.add("", ("name",), problem)
    if robot.board == "pico":
        if robot.drive.driver not in pico_pinout():
            p.add(
                "drive", ("driver",), f"= {robot.drive.driver!r}: the Pico firmware drives {', '.join(pico_pinout())}"
            )
        if len(robot.wiring.encoders) != robot.drive.channels:
            p.add("encoders", ("pins",), "the Pico firmware needs encoder pins for each wheel channel")
        return p.found
    if robot.board not in ("uno", "mega2560"):
        p.add("", ("board",), f"= {robot.board!r}: the firmware builds for uno, mega2560 or pico")
        return p.found
    example = example_for(robot)
    if example is None:
        drives = ", ".join(f"{kind} with {driver}" for kind, driver in examples())
        p.add("drive", ("driver",), f"= {robot.drive.driver!r}: no example sketch drives it yet ({drives})")
        return p.found
    known = library_examples()
    if example not in known:
        why = f"not an example sketch of the library (one of {', '.join(known)})"
        p.add("firmware", ("example",), f"= {example!r}: {why}")
        return p.found
    _pins_problems(p, example)
    return p.found


def load_robot(path: str | Path) -> RobotFile:
    """The robot file at `path`, checked as a file and as a firmware; RobotFileError lists every
    problem (nothing is built or flashed then)."""
    problems = check(path)
    if problems:
        raise RobotFileError(problems)
    robot = load(path)
    problems = firmware_problems(robot)
    if problems:
        raise RobotFileError(problems)
    return robot


def robot_board(robot: RobotFile, board: str | None) -> BoardSpec:
    """The file's board; `board` (a --board option) must agree with it."""
    if board is not None and board != robot.board:
        raise FirmwareError(f"{robot.path} is for the {robot.board}, not the {board}: leave --board out")
    return board_spec(robot.board)


def write_sketch(robot: RobotFile, folder: Path, *, force: bool = False) -> Path:
    """`folder` as a sketch: the fitting example's .ino (named after the folder, as the IDE wants)
    and `robot_profile.h` from the file. Refuses to overwrite either unless `force`."""
    if not SKETCH_NAME.match(folder.name):
        raise FirmwareError(f"{folder.name!r} cannot name a sketch: letters, digits, _ . - (a letter or digit first)")
    example = example_for(robot)
    if example is None:  # load_robot has refused it already
        raise FirmwareError(f"no example sketch drives {robot.drive.driver}")
    ino, header = folder / f"{folder.name}.ino", folder / "robot_profile.h"
    existing = [str(f) for f in (ino, header) if f.exists()]
    if existing and not force:
        raise FirmwareError(f"{', '.join(existing)} exists (--force to overwrite)")
    source = example_dir(example) / f"{example}.ino"
    folder.mkdir(parents=True, exist_ok=True)
    ino.write_text(sketch_text(robot, example, source.read_text(encoding="utf-8")), encoding="utf-8")
    header.write_text(profile_header(robot, example, robot.path), encoding="utf-8")
    return folder


def _about(robot: RobotFile) -> str:
    """The robot in a few words, from its file (what the example's own first comment says of the
    reference robot)."""
    parts = [f"{robot.drive.kind} drive ({robot.drive.driver}) on the {robot.board}"]
    st = robot.steering
    if st is not None:
        step = f", {st.step_deg:g} degree steps" if st.step_deg else ""
        parts.append(f"steering servo {st.min_deg:g}..{st.max_deg:g} degrees, centre {st.center_deg:g}{step}")
    enc = robot.encoders
    if robot.wiring.encoders:
        parts.append(f"{len(robot.wiring.encoders)} encoder(s), {enc.counts_per_rev} counts/rev ({enc.decoding})")
    parts.append(f"wheels {robot.geometry.wheel_diameter_m * 1000:g} mm")
    parts.append(f"{robot.feedback.mode} feedback")
    return f"{robot.name}: " + ", ".join(parts) + "."


def sketch_text(robot: RobotFile, example: str, source: str) -> str:
    """The example's sketch for `robot`: its first comment, which describes the reference robot,
    replaced by one from the file; the code and the comments on it kept."""
    lines = source.splitlines(keepends=True)
    body = 0
    while body < len(lines) and lines[body].startswith("//"):
        body += 1
    paragraphs = [_about(robot)] + ([robot.description] if robot.description else [])
    paragraphs.append(
        f"From {robot.path}: the {example} example, its robot_profile.h generated from that file "
        f"(`roverlink firmware sketch --robot {robot.path}`): edit the file, not the header. Wiring, timers "
        "and flashing: docs/firmware.md."
    )
    head = "//\n".join(
        textwrap.fill(
            text, 100, initial_indent="// ", subsequent_indent="// ", break_on_hyphens=False, break_long_words=False
        )
        + "\n"
        for text in paragraphs
    )
    # The code's own comments name where the header comes from: the user's file, not the reference's.
    reference = f"generated from {example_reference(example)}.toml"
    rest = "".join(lines[body:]).replace(reference, f"generated from {Path(robot.path).name}")
    return head + ("" if rest.startswith("\n") else "\n") + rest


def build_folder(path: str | Path) -> Path:
    """Where `firmware build --robot` keeps the sketch and firmware of the file at `path`: one
    folder per file (by its absolute path)."""
    resolved = str(Path(path).resolve())
    stem = re.sub(r"[^A-Za-z0-9_.-]", "_", Path(path).stem) or "robot"
    return BUILD_ROOT / "robots" / f"{stem}-{hashlib.sha256(resolved.encode()).hexdigest()[:10]}"


def build_sketch_dir(robot: RobotFile) -> Path:
    """The file's sketch in its build folder, written afresh (named after the example it copies)."""
    example = example_for(robot) or ""
    return write_sketch(robot, build_folder(robot.path) / example, force=True)
