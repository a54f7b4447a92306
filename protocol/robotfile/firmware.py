"""A robot file as the firmware example's `robot_profile.h`: the one writer of that header, for the
reference robots' files (`python -m protocol generate`, into arduino/RoverLink/examples/*/) and for
a user's file (`roverlink firmware`).

    >>> from protocol.robotfile import load, reference_path
    >>> text = profile_header(load(reference_path("picar")), "AckermannPiCar", "picar.toml")
    >>> 'NAME[] = "picar"' in text
    True

The firmware reports the file's robot name (IDENTITY robot_name: at most 24 ASCII characters,
`name_problem`); a reference robot's example reports the example's name. The example that fits a
file is its `[firmware] example`, else the one a reference robot of the same drive and driver names
(`example_for`).
"""

from __future__ import annotations

import struct
from functools import cache
from pathlib import Path

from protocol.generated.enums import Capability
from protocol.generated.messages import Identity
from protocol.generated.profiles import Wiring
from protocol.generator import loader
from protocol.generator import wiring as rules
from protocol.generator.emit.common import GENERATOR
from protocol.generator.hardware import pwm_facts
from protocol.generator.model import PRIMITIVES, Spec
from protocol.robotfile import REFERENCES, load, reference_path
from protocol.robotfile.model import RobotFile
from protocol.robotfile.pico import cpp_wiring
from protocol.robotfile.schema import LIGHTS

_SPEC = Path(__file__).resolve().parents[1] / "spec" / "roverlink.toml"
NAME_MAX = next(f.max_len for f in Identity.FIELDS if f.name == "robot_name") or 0
"""Longest robot name IDENTITY carries."""
ULTRASONIC_HZ = 31373
"""What hal/avr/motors.h's pwm_ultrasonic() sets a timer to (prescaler 1, 8-bit phase correct)."""


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


def pin_label(number: int, board: str) -> str:
    """A pin as the board names it: 9, or A0 for the first analog pin (`board`: uno, mega2560), or
    GP9 on the Pico."""
    if board == "pico":
        return f"GP{number}"
    first_analog = rules.BOARD_PINS[board.upper()].first_analog
    return f"A{number - first_analog}" if number >= first_analog else str(number)


def channel_names(w: Wiring) -> tuple[str, ...]:
    """Names of the wheel channels in generated code: left and right, or motor for one."""
    return ("left", "right") if max(len(w.motors), len(w.encoders)) == 2 else ("motor",)


def pin_constants(robot: RobotFile) -> list[tuple[str, int, str, str]]:
    """(C++ constant name, pin number, pin as the board names it, what it serves) for every wired
    pin, in the file's order."""
    w, names = robot.wiring, channel_names(robot.wiring)
    out: list[tuple[str, int, str]] = []
    for i, motor in enumerate(w.motors):
        for role, pin in motor.pins:
            out.append((f"{names[i].upper()}_{role.upper()}", pin, f"{names[i]} motor, {motor.kind} {role}"))
    for i, enc in enumerate(w.encoders):
        for role, pin in enc.pins:
            out.append((f"{names[i].upper()}_ENC_{role.upper()}", pin, f"{names[i]} encoder, channel {role}"))
    for name, pin in zip(LIGHTS, w.led_pins, strict=False):
        out.append((f"LED_{name.upper()}", pin, f"LED {name.replace('_', ' ')}"))
    if w.esc_pin is not None:
        out.append(("ESC_PIN", w.esc_pin, "ESC signal"))
    if w.servo_pin is not None:
        out.append(("STEERING_PIN", w.servo_pin, "steering servo signal"))
    if robot.board != "pico":  # the Pico's noise is its ring oscillator's
        out.append(("ENTROPY_PIN", w.entropy_pin, "entropy, leave unconnected: its ADC noise seeds the boot_id"))
    return [(name, pin, pin_label(pin, robot.board), what) for name, pin, what in out]


def _cpp_pins(robot: RobotFile, source: str) -> str:
    numbering = "GPIO numbers" if robot.board == "pico" else "Arduino pin numbers (A<n> as its number on this board)"
    o = [f"// Wiring ({source}): {numbering}.\n"]
    for name, number, label, what in pin_constants(robot):
        analog = f" ({label})" if label.startswith("A") else ""
        o.append(f"static const uint8_t {name} = {number};  // {what}{analog}\n")
    return "".join(o) + "\n"


def fast_pwm_pins(robot: RobotFile) -> list[int]:
    """The motor PWM pins whose timer the sketch must set: every one whose driver needs another
    frequency than the core's, on whichever timer it is (hardware.toml's PWM tables)."""
    facts, board = pwm_facts(), robot.board.upper()
    fast: list[int] = []
    for motor in robot.wiring.motors:
        for role, pin in motor.pins:
            if role not in rules.PWM_ROLES:
                continue
            timer, hz = facts.timer_of(board, pin), facts.hz(board, pin, motor.kind)
            if timer is None or hz is None or hz == timer.hz[0]:
                continue  # no facts for the board, or the core's own frequency
            if hz != ULTRASONIC_HZ:
                raise ValueError(f"{robot.path}: pin {pin} at {hz} Hz: the firmware sets {ULTRASONIC_HZ} Hz only")
            if pin not in fast:
                fast.append(pin)
    return fast


def _cpp_pwm(robot: RobotFile) -> str:
    if robot.board == "pico":
        return cpp_wiring(robot, _motor_hz(robot))
    fast = fast_pwm_pins(robot)
    if not fast:
        return ""
    o = ["// Motor PWM pins whose driver runs above the core's frequency (protocol/spec/hardware.toml):\n"]
    o.append(f"// the sketch sets each one's timer to {ULTRASONIC_HZ} Hz (pwm_ultrasonic), whichever timer it is on.\n")
    o.append(f"static const uint8_t FAST_PWM_PINS[] = {{{', '.join(map(str, fast))}}};\n")
    o.append(f"static const uint8_t FAST_PWM_PIN_COUNT = {len(fast)};\n\n")
    return "".join(o)


def _motor_hz(robot: RobotFile) -> int:
    """The frequency the file's motor PWM pins run at (hardware.toml; 0 without DC motors)."""
    facts, board = pwm_facts(), robot.board.upper()
    found = {
        facts.hz(board, pin, m.kind) for m in robot.wiring.motors for role, pin in m.pins if role in rules.PWM_ROLES
    }
    if len(found) > 1 or None in found:
        raise ValueError(f"{robot.path}: the motor PWM pins need one frequency, not {sorted(map(str, found))}")
    return int(found.pop() or 0) if found else 0


def _cpp_defaults(spec: Spec, robot: RobotFile, source: str) -> str:
    config, pid = robot.config(), robot.pid_gains()
    o = ["// The configuration as a SET_CONFIG payload in flash, unpacked when asked for: a static struct\n"]
    o.append("// would cost SRAM for the whole run on AVR, and code setting each field more flash than this.\n")
    o.append("// static: two profiles linked into one test program must not merge.\n")
    o.append("static const uint8_t DEFAULT_CONFIG[] ROVERLINK_PROGMEM = {\n")
    for f in spec.message("SET_CONFIG").fields:
        value = getattr(config, f.name)
        data = struct.pack("<" + PRIMITIVES[f.prim][2], int(value))
        shown = value.name if f.enum else value
        o.append(f"    {', '.join(f'0x{b:02X}' for b in data)},  // {f.name} = {shown}\n")
    o.append("};\n")
    o.append(
        'static_assert(sizeof DEFAULT_CONFIG == roverlink::proto::SetConfig::PAYLOAD_SIZE, "a SET_CONFIG payload");\n\n'
    )
    o.append("static inline roverlink::proto::SetConfig default_config() {\n")
    o.append("    uint8_t payload[sizeof DEFAULT_CONFIG];\n")
    o.append("    for (uint8_t i = 0; i < sizeof payload; ++i) {\n")
    o.append("        payload[i] = ROVERLINK_READ_BYTE(DEFAULT_CONFIG + i);\n    }\n")
    o.append("    roverlink::proto::SetConfig c = roverlink::proto::SetConfig();\n")
    o.append(f"    roverlink::proto::unpack(payload, sizeof payload, c);  // valid: {source} is checked\n")
    o.append("    return c;\n}\n\n")
    o.append("static inline roverlink::proto::SetPid default_pid() {\n    roverlink::proto::SetPid p;\n")
    o.append("    p.wheel = roverlink::proto::PID_ALL_WHEELS;\n")
    for f in spec.message("SET_PID").fields:
        if f.name != "wheel":
            o.append(f"    p.{f.name} = {float(getattr(pid, f.name))!r}f;\n")
    o.append("    return p;\n}\n\n}  // namespace robot_profile\n\n")
    return "".join(o)


def profile_header(
    robot: RobotFile, example: str, source: str, *, reference: bool = False, spec: Spec | None = None
) -> str:
    """`robot_profile.h` for `example` with the file's defaults, pins and name (`source`: the file
    as the header's first line names it). A `reference` robot's header is the generator's (its
    example reports the example's name, which the SDK maps back to the robot); another file's
    is `roverlink firmware`'s and reports the file's robot name."""
    spec = spec or _spec()
    tool = f"`{GENERATOR}`" if reference else "`roverlink firmware`; edit that file instead"
    o = [f"// DO NOT EDIT: generated from {source} by {tool}.\n// spec hash: 0x{spec.spec_hash:08X}\n"]
    about = f": {robot.description}" if robot.description else ""
    o.append(f"// Defaults of {robot.name} ({example} example){about}\n")
    o.append(f"// Change them over the link (SET_CONFIG, SET_PID) and SAVE_CONFIG, or edit {source}.\n")
    guard = f"ROVERLINK_EXAMPLE_{example.upper()}_PROFILE_H"
    o.append(f"#ifndef {guard}\n#define {guard}\n\n#include <RoverLink.h>\n\nnamespace robot_profile {{\n\n")
    o.append(f'static const char NAME[] = "{example if reference else robot.name}";\n')
    o.append(f"static const roverlink::proto::Board BOARD = roverlink::proto::Board::{robot.board.upper()};\n")
    caps = " | ".join(f"roverlink::proto::Capability::{c.name}" for c in Capability if c in robot.capabilities())
    o.append(f"static const uint16_t CAPABILITIES = {caps or '0'};\n")
    o.append(
        "static const roverlink::proto::FeedbackMode FEEDBACK_MODE = "
        f"roverlink::proto::FeedbackMode::{robot.feedback_mode().name};\n"
        "static const roverlink::proto::LightsMode LIGHTS_MODE = "
        f"roverlink::proto::LightsMode::{robot.lights_mode().name};  // turn signals at power-up\n\n"
    )
    o.append(_cpp_pins(robot, source))
    o.append(_cpp_pwm(robot))
    o.append(_cpp_defaults(spec, robot, source))
    o.append(f"#endif  // {guard}\n")
    return "".join(o)


@cache
def _references() -> tuple[RobotFile, ...]:
    return tuple(load(reference_path(name)) for name in REFERENCES)


def examples() -> dict[tuple[str, str], str]:
    """The library's example sketch for each (drive kind, driver), as the reference robots' files
    name them (`[firmware] example`): what a robot file's firmware is built from."""
    out: dict[tuple[str, str], str] = {}
    for robot in _references():
        out.setdefault((robot.drive.kind, robot.drive.driver), robot.example)
    return out


def example_reference(example: str) -> str | None:
    """The reference robot whose file names `example` (None: none does)."""
    return next((r.name for r in _references() if r.example == example), None)


def example_for(robot: RobotFile) -> str | None:
    """The example sketch the file's firmware is built from: its `[firmware] example`, else the one
    for its drive and driver (None: no example drives them)."""
    return robot.example or examples().get((robot.drive.kind, robot.drive.driver))
