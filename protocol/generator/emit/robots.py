"""Emit the reference robots from their robot files (protocol/robots/*.toml): the SDK/emulator
profiles, each firmware example's robot_profile.h (the one header writer, protocol.robotfile.firmware)
and docs/robots.md."""

from __future__ import annotations

from protocol.generated.enums import Capability
from protocol.generated.profiles import WiredPart, Wiring
from protocol.generator.emit.common import GENERATOR, num
from protocol.generator.model import Field, Spec
from protocol.robotfile import RobotFile
from protocol.robotfile.firmware import pin_constants, profile_header

ROBOTS_PATH = "protocol/robots/*.toml"


def _banner(spec: Spec, comment: str) -> str:
    return (
        f"{comment} DO NOT EDIT: generated from {ROBOTS_PATH} and {spec.path} by `{GENERATOR}`.\n"
        f"{comment} spec hash: 0x{spec.spec_hash:08X}\n"
    )


def emit(spec: Spec, robots: tuple[RobotFile, ...]) -> dict[str, str]:
    """`robots`: the reference robots' files, read with their repository-relative paths."""
    out = {"protocol/generated/profiles.py": _python(spec, robots), "docs/robots.md": _docs(spec, robots)}
    for r in robots:
        header = profile_header(r, r.example, r.path, reference=True, spec=spec)
        out[f"arduino/RoverLink/examples/{r.example}/robot_profile.h"] = header
    return out


def _kinematics(r: RobotFile) -> str:
    return "diff" if r.drive.kind == "differential" else "ackermann"


def _defaults(spec: Spec, r: RobotFile, python: bool) -> tuple[list[tuple[Field, str]], list[tuple[Field, str]]]:
    """(SET_CONFIG fields, SET_PID gains), each (field, its value) in wire order, as Python
    (`python`: an enum as SafeState.BRAKE) or the docs (BRAKE) write it."""
    config, pid = r.config(), r.pid_gains()
    fields = []
    for f in spec.message("SET_CONFIG").fields:
        value = getattr(config, f.name)
        shown = (f"{f.enum.name}.{value.name}" if python else value.name) if f.enum else num(value)
        fields.append((f, shown))
    gains = [(f, num(float(getattr(pid, f.name)))) for f in spec.message("SET_PID").fields if f.name != "wheel"]
    return fields, gains


def _python(spec: Spec, robots: tuple[RobotFile, ...]) -> str:
    o = [_banner(spec, "#")]
    o.append('"""Reference robot profiles by name: firmware defaults, kinematics, feedback mode, footprint and\n')
    o.append('sensor mounts (from protocol/robots/*.toml)."""\n\n')
    o.append("from __future__ import annotations\n\nfrom dataclasses import dataclass\n\n")
    o.append("from protocol.generated.enums import Board, Capability, FeedbackMode, LightsMode, SafeState\n")
    o.append("from protocol.generated.messages import SetConfig, SetPid\n")
    o.append("from protocol.sensors import Mount, RobotSensors\n\n\n")
    o.extend(_py_class(*c) for c in _PY_CLASSES)
    o[-1] = o[-1].rstrip("\n") + "\n"
    o.append("\n\nPROFILES: dict[str, RobotProfile] = {\n")
    for r in robots:
        caps = " | ".join(f"Capability.{c.name}" for c in Capability if c in r.capabilities()) or "Capability(0)"
        fields, gains = _defaults(spec, r, python=True)
        cfg = ", ".join(f"{f.name}={value}" for f, value in fields)
        pid = ", ".join(f"{f.name}={value}" for f, value in gains)
        o.append(f'    "{r.name}": RobotProfile(\n')
        o.append(f'        name="{r.name}",\n        example="{r.example}",\n        doc={r.description!r},\n')
        o.append(f"        board=Board.{r.board.upper()},\n        capabilities={caps},\n")
        o.append(f'        kinematics="{_kinematics(r)}",\n')
        o.append(f"        feedback_mode=FeedbackMode.{r.feedback_mode().name},\n")
        o.append(f"        lights_mode=LightsMode.{r.lights_mode().name},\n")
        geo = r.geometry
        o.append(f"        track_m={num(geo.track_m)},\n        wheelbase_m={num(geo.wheelbase_m)},\n")
        o.append(f"        wheel_diameter_m={num(geo.wheel_diameter_m)},\n")
        o.append(f"        encoder_cpr={r.encoders.counts_per_rev},\n")
        o.append(f"        config=SetConfig({cfg}),\n")
        o.append(f"        pid=SetPid(wheel=255, {pid}),\n")
        o.append(f"        wiring={_py_wiring(r.wiring)},\n    ),\n")
    o.append("}\n")
    o.append('"""Reference robots by profile name."""\n')
    o.append("\nROBOT_SENSORS: dict[str, RobotSensors] = {\n")
    for r in robots:
        body = r.sensors()
        o.append(f'    "{r.name}": RobotSensors(\n        profile="{r.name}",\n')
        o.append(f"        footprint_radius_m={num(body.footprint_radius_m)},\n")
        o.append(f"        footprint_x_m={num(body.footprint_x_m)},\n        mounts=(\n")
        for m in body.mounts:
            place = ", ".join(f"{k}={num(getattr(m, k))}" for k in ("x_m", "y_m", "z_m", "yaw_deg"))
            o.append(f'            Mount(device="{m.device}", name="{m.name}", {place}),\n')
        o.append("        ),\n    ),\n")
    o.append("}\n")
    o.append('"""Each reference robot\'s footprint (as a disc) and sensor mounts, by profile name."""\n')
    return "".join(o)


_PY_CLASSES: tuple[tuple[str, str, tuple[tuple[str, str, str], ...], str], ...] = (
    (
        "WiredPart",
        "A DC motor driver channel or an encoder, and the Arduino pins it is wired to.",
        (
            ("kind", "str", 'The motor\'s driver (TB6612, L298N, BTS7960) or "encoder".'),
            (
                "pins",
                "tuple[tuple[str, int], ...]",
                "(role, Arduino pin): pwm, in1, in2, standby / rpwm, lpwm, r_en, l_en / a, b.",
            ),
        ),
        "\n    def pin(self, role: str) -> int:\n        return dict(self.pins)[role]\n",
    ),
    (
        "Wiring",
        "Which Arduino pin serves which part (a robot file's pins: docs/robot-file.md).",
        (
            (
                "motors",
                "tuple[WiredPart, ...]",
                "DC motor driver channels, in wheel-channel order (none behind an ESC).",
            ),
            ("encoders", "tuple[WiredPart, ...]", "Quadrature encoders, in wheel-channel order."),
            ("esc_pin", "int | None", "ESC signal."),
            ("servo_pin", "int | None", "Steering servo signal."),
            ("led_pins", "tuple[int, ...]", "One per Lights bit, in bit order (none without turn signals)."),
            ("entropy_pin", "int", "Analog pin left open: its noise seeds the boot_id."),
        ),
        "",
    ),
    (
        "RobotProfile",
        "One reference robot. `config` and `pid` are the firmware example's defaults.",
        (
            ("name", "str", "Profile name (emulator and SDK)."),
            ("example", "str", "Firmware example (sketch folder) with these defaults."),
            ("doc", "str", "What the robot is."),
            ("board", "Board", "Board the example targets."),
            ("capabilities", "Capability", "Capabilities the example reports."),
            ("kinematics", "str", '"diff" or "ackermann".'),
            ("feedback_mode", "FeedbackMode", "Feedback mode the robot is used with."),
            ("lights_mode", "LightsMode", "The turn signals' mode at power-up and at each new session."),
            ("track_m", "float", "Distance between the left and right wheels."),
            ("wheelbase_m", "float", "Distance between the axles (Ackermann; 0 for diff-drive)."),
            ("wheel_diameter_m", "float", "Driven wheel diameter."),
            ("encoder_cpr", "int", "Encoder counts per wheel revolution."),
            ("config", "SetConfig", "Default configuration."),
            ("pid", "SetPid", "Default PID gains (all wheels)."),
            ("wiring", "Wiring", "Which Arduino pin serves which part."),
        ),
        "",
    ),
)
"""The generated profile module's classes: (name, doc, fields as (name, type, doc), extra body)."""


def _py_class(name: str, doc: str, fields: tuple[tuple[str, str, str], ...], extra: str) -> str:
    o = [f'@dataclass(frozen=True, slots=True)\nclass {name}:\n    """{doc}"""\n\n']
    o.extend(f'    {field}: {typ}\n    """{text}"""\n' for field, typ, text in fields)
    return "".join(o) + extra + "\n\n"


def _py_part(p: WiredPart) -> str:
    pins = ", ".join(f'("{role}", {pin})' for role, pin in p.pins)
    return f'WiredPart("{p.kind}", ({pins},))'


def _py_wiring(w: Wiring) -> str:
    motors = "".join(f"{_py_part(p)}, " for p in w.motors)
    encoders = "".join(f"{_py_part(p)}, " for p in w.encoders)
    leds = "".join(f"{pin}, " for pin in w.led_pins)
    return (
        f"Wiring(\n            motors=({motors.rstrip()}),\n            encoders=({encoders.rstrip()}),\n"
        f"            esc_pin={w.esc_pin},\n            servo_pin={w.servo_pin},\n"
        f"            led_pins=({leds.rstrip()}),\n"
        f"            entropy_pin={w.entropy_pin},\n        )"
    )


def _docs(spec: Spec, robots: tuple[RobotFile, ...]) -> str:
    o = [f"<!-- DO NOT EDIT: generated from {ROBOTS_PATH} and {spec.path} by `{GENERATOR}`. -->\n"]
    o.append(f"<!-- spec hash: 0x{spec.spec_hash:08X} -->\n\n# Reference robots\n\n")
    o.append("Each reference robot is one robot file, `protocol/robots/<name>.toml` (the format: ")
    o.append("[robot-file.md](robot-file.md)); its firmware example's `robot_profile.h`, its emulator and SDK ")
    o.append("profile and this page are generated from it. A new file there is a new reference robot.\n\n")
    o.append("To adapt one to your robot, copy its file with `roverlink robot new my_robot.toml --from <name>`, ")
    o.append(
        "change it, and run `roverlink robot check my_robot.toml` (every key: [robot-file.md](robot-file.md)).\n\n"
    )
    o.append("| | " + " | ".join(f"`{r.name}`" for r in robots) + " |\n|---|" + "---|" * len(robots) + "\n")
    rows: list[tuple[str, list[str]]] = [
        ("firmware example", [f"`{r.example}`" for r in robots]),
        ("board", [r.board.upper() for r in robots]),
        ("kinematics", [_kinematics(r) for r in robots]),
        ("feedback mode", [r.feedback_mode().name for r in robots]),
        ("capabilities", [", ".join(c.name or "" for c in Capability if c in r.capabilities()) for r in robots]),
        ("track (mm)", [num(r.geometry.track_m * 1000) for r in robots]),
        ("wheelbase (mm)", [num(r.geometry.wheelbase_m * 1000) for r in robots]),
    ]
    values = [[*fields, *gains] for fields, gains in (_defaults(spec, r, python=False) for r in robots)]
    for i, (f, _) in enumerate(values[0]):
        unit = f" ({f.unit})" if f.unit else ""
        rows.append((f"`{f.name}`{unit}", [v[i][1] for v in values]))
    for label, cells in rows:
        o.append(f"| {label} | " + " | ".join(cells) + " |\n")
    o.append("\n")
    for r in robots:
        o.append(f"- **{r.name}**: {r.description}\n")
    o.append("\n## Wiring\n\nArduino pins as the examples use them (`robot_profile.h` holds them as constants; the ")
    o.append("simavr backend maps them to the MCU's registers). Timers, interrupts and power: docs/firmware.md, ")
    o.append('"Boards, wiring and flashing".\n')
    for r in robots:
        o.append(f"\n### {r.example} (`{r.name}`, {r.board.upper()})\n\n| pin | serves | constant |\n|---|---|---|\n")
        for name, _, label, what in pin_constants(r):
            o.append(f"| {label} | {what} | `{name}` |\n")
    return "".join(o)
