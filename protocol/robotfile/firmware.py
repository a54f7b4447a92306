"""A robot file as the firmware example's `robot_profile.h`: the header the generator writes for the
reference robots from robots.toml (protocol/generator/emit/robots.py), written from the file.

    >>> from protocol.robotfile import load, reference_path
    >>> text = profile_header(load(reference_path("picar")), "AckermannPiCar", "picar.toml")
    >>> 'NAME[] = "picar"' in text
    True

The firmware reports the file's robot name (IDENTITY robot_name: at most 24 ASCII characters,
`name_problem`). The example that fits the file is the firmware build's choice (roverlink.firmware).
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

from protocol.generated.enums import Capability
from protocol.generated.messages import Identity
from protocol.generated.profiles import WiredPart, Wiring
from protocol.generator import loader
from protocol.generator import wiring as rules
from protocol.generator.emit.robots import profile_header as emit_header
from protocol.generator.model import Spec
from protocol.generator.robots import Robot
from protocol.robotfile.model import RobotFile
from protocol.robotfile.schema import LIGHTS

_SPEC = Path(__file__).resolve().parents[1] / "spec" / "roverlink.toml"
NAME_MAX = next(f.max_len for f in Identity.FIELDS if f.name == "robot_name") or 0
"""Longest robot name IDENTITY carries."""


@cache
def _spec() -> Spec:
    return loader.load(_SPEC, _SPEC.parents[2])


def name_problem(name: str) -> str:
    """Why the firmware cannot report `name` as its robot name ("" when it can)."""
    if not name.isascii() or not name.isprintable() or '"' in name or "\\" in name:
        return f"= {name!r}: the firmware reports it as ASCII text: letters, digits, spaces and -_.()+ only"
    if len(name) > NAME_MAX:
        return f"= {name!r}: the firmware reports at most {NAME_MAX} characters (it has {len(name)})"
    return ""


def _pin(number: int, board: str) -> rules.Pin:
    first_analog = rules.BOARD_PINS[board].first_analog
    label = f"A{number - first_analog}" if number >= first_analog else str(number)
    return rules.Pin(number, label)


def _part(part: WiredPart, board: str) -> rules.Part:
    return rules.Part(part.kind, tuple((role, _pin(n, board)) for role, n in part.pins))


def generator_wiring(w: Wiring, board: str) -> rules.Wiring:
    """The file's pins as the generator's wiring (pin labels as the board names them: A0...)."""
    return rules.Wiring(
        motors=tuple(_part(m, board) for m in w.motors),
        encoders=tuple(_part(e, board) for e in w.encoders),
        esc=_pin(w.esc_pin, board) if w.esc_pin is not None else None,
        servo=_pin(w.servo_pin, board) if w.servo_pin is not None else None,
        # no lights, or all four (the file is checked)
        leds=tuple((name, _pin(n, board)) for name, n in zip(LIGHTS, w.led_pins, strict=False)),
        entropy=_pin(w.entropy_pin, board),
    )


def generator_robot(robot: RobotFile, example: str) -> Robot:
    """The file as the generator's reference-robot record (`example`: the sketch it configures).
    The board must be one with pins (uno, mega2560)."""
    spec = _spec()
    board = robot.board.upper()
    config, pid = robot.config(), robot.pid_gains()

    def value(v: object) -> object:
        return getattr(v, "name", v)  # enum fields by name, as robots.toml writes them

    caps = robot.capabilities()
    return Robot(
        name=robot.name,
        example=example,
        doc=robot.description,
        board=board,
        capabilities=tuple(c.name or "" for c in Capability if c in caps),
        kinematics="diff" if robot.drive.kind == "differential" else "ackermann",
        feedback_mode=robot.feedback_mode().name,
        lights_mode=robot.lights_mode().name,
        track_mm=robot.track_m * 1000,
        wheelbase_mm=robot.geometry.wheelbase_m * 1000,
        config=tuple((f, value(getattr(config, f.name))) for f in spec.message("SET_CONFIG").fields),
        pid=tuple((f, getattr(pid, f.name)) for f in spec.message("SET_PID").fields if f.name != "wheel"),
        wiring=generator_wiring(robot.wiring, board),
    )


def profile_header(robot: RobotFile, example: str, source: str) -> str:
    """`robot_profile.h` for `example` with the file's defaults, pins and name (`source`: the file
    as the header's first line names it)."""
    return emit_header(_spec(), generator_robot(robot, example), source)


EXAMPLES: dict[tuple[str, str], str] = {
    ("differential", "TB6612"): "DiffDriveTB6612",
    ("differential", "BTS7960"): "DiffDriveBTS7960",
    ("ackermann", "ESC+servo"): "AckermannPiCar",
}
"""The library's example sketch for each (drive kind, driver): what a robot file's firmware is built from."""


def example_for(robot: RobotFile) -> str | None:
    """The example sketch that drives the file's drive and driver (None: no example does)."""
    return EXAMPLES.get((robot.drive.kind, robot.drive.driver))
