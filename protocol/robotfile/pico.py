"""A robot file moved to a Raspberry Pi Pico: the same robot with `board = "pico"` and its drive on
the Pico pinout of its driver (protocol/spec/hardware.toml, [[pico_pinout]]); every other line,
comment and value as it was. What `roverlink robot new --from NAME --board pico` writes and what
`roverlink emulate --backend rp2040 --profile NAME` runs; the reader then checks the result as it
checks any file.

    text = on_pico(reference_path("diffdrive-tb6612").read_text())
"""

from __future__ import annotations

import re

from protocol.generator.hardware import PinOut, pico_pinout
from protocol.robotfile.errors import Problem, RobotFileError
from protocol.robotfile.model import RobotFile
from protocol.robotfile.schema import LIGHTS
from protocol.toml import tomllib

_SECTION = re.compile(r"\s*\[([A-Za-z0-9_.]+)\]\s*(#.*)?$")
_KEY = re.compile(r"(\s*)([A-Za-z0-9_]+)(\s*=\s*)(.*?)(\s*#.*)?$")
# How the AVR boards are named in a description, so a moved robot's sentence names the Pico.
_AVR_NAMES = re.compile(r"\b(?:Arduino )?(?:Mega 2560|Mega2560|Uno)\b")


def _table(part: tuple[tuple[str, int], ...]) -> str:
    return "{ " + ", ".join(f"{role} = {pin}" for role, pin in part) + " }"


def _array(parts: tuple[tuple[tuple[str, int], ...], ...], count: int) -> list[str]:
    return [f"    {_table(p)}," for p in parts[:count]]


def on_pico(text: str, path: str = "<robot file>") -> str:
    """`text` (a robot file) with the Pico as its board and its drive on the Pico pinout."""
    data = tomllib.loads(text)
    driver = str(data.get("drive", {}).get("driver", ""))
    pinout: PinOut | None = pico_pinout().get(driver)
    if pinout is None:
        allowed = ", ".join(pico_pinout())
        raise RobotFileError([Problem(path, "drive.driver", None, f"= {driver!r}: no Pico pinout (one of {allowed})")])
    channels = len(data.get("drive", {}).get("motors", [])) or len(data.get("encoders", {}).get("pins", [])) or 1
    out: list[str] = []
    section = ""
    skipping = False  # inside a multi-line array being replaced
    for line in text.splitlines():
        if skipping:
            skipping = not line.strip().startswith("]")
            continue
        found = _SECTION.match(line)
        if found:
            section = found.group(1)
            out.append(line)
            continue
        key = _KEY.match(line)
        if key is None or line.lstrip().startswith("#"):
            out.append(line)
            continue
        indent, name, eq, value, comment = key.groups()
        comment = comment or ""
        replaced = _replacement(section, name, value, pinout, channels)
        if replaced is None:
            out.append(line)
        elif isinstance(replaced, list):
            out.append(f"{indent}{name}{eq}[{comment}")
            out += replaced
            out.append("]")
            skipping = value.strip() == "["  # the old array's lines up to its "]"
        else:
            out.append(f"{indent}{name}{eq}{replaced}{comment}")
    return "\n".join(out) + "\n"


def _replacement(section: str, name: str, value: str, pinout: PinOut, channels: int) -> str | list[str] | None:
    if section == "" and name == "board":
        return '"pico"'
    if section == "" and name == "description":
        return _AVR_NAMES.sub("Raspberry Pi Pico", value)
    if section == "drive" and name == "motors":
        return _array(pinout.motors, channels)
    if section == "encoders" and name == "pins":
        return _array(pinout.encoders, channels)
    if section == "lights" and name in LIGHTS:
        return str(pinout.lights[LIGHTS.index(name)])
    if section == "esc" and name == "pin" and pinout.esc is not None:
        return str(pinout.esc)
    if section == "steering" and name == "pin" and pinout.steering is not None:
        return str(pinout.steering)
    return None


def cpp_wiring(robot: RobotFile, motor_hz: int) -> str:
    """robot_profile.h's WIRING for the Pico program (hal/rp2040/board.h, Wiring): every part's pins
    in one table, `motor_hz` the motors' PWM frequency."""
    w, ns = robot.wiring, "roverlink::rp2040"
    none = f"{ns}::NO_PIN"

    def pin(n: int | None) -> str:
        return none if n is None else str(n)

    motors = []
    for m in w.motors:
        roles: dict[str, int | None] = dict(m.pins)
        if m.kind == "BTS7960":
            kind, pins = "BTS7960", [roles["rpwm"], roles["lpwm"], roles["r_en"], roles["l_en"]]
        else:
            kind, pins = "HBRIDGE", [roles["pwm"], roles["in1"], roles["in2"], roles.get("standby")]
        motors.append(f"{{{ns}::Driver::{kind}, {{{', '.join(pin(p) for p in pins)}}}}}")
    encoders = [f"{{{dict(e.pins)['a']}, {dict(e.pins)['b']}}}" for e in w.encoders]
    resolution = robot.encoders.decoding.upper()
    o = ["// Every part's pins for the Pico program (hal/rp2040/board.h, Wiring).\n"]
    o.append(f"static const {ns}::Wiring WIRING = {{\n")
    o.append(f"    {len(motors)}, {{{', '.join(motors)}}},  // motors\n")
    o.append(f"    {motor_hz},  // motor PWM Hz (protocol/spec/hardware.toml)\n")
    o.append(f"    {len(encoders)}, {{{', '.join(encoders)}}},  // encoders a, b\n")
    o.append(f"    roverlink::quadrature::Resolution::{resolution},\n")
    o.append(f"    {pin(w.esc_pin)}, {pin(w.servo_pin)},  // ESC, steering servo\n")
    o.append(f"    {len(w.led_pins)}, {{{', '.join(map(str, w.led_pins))}}},  // LEDs\n")
    o.append("};\n\n")
    return "".join(o)
