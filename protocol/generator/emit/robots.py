"""Emit the reference robots: SDK/emulator profiles, firmware example defaults, docs/robots.md."""

from __future__ import annotations

import struct

from protocol.generator.emit.common import GENERATOR, num
from protocol.generator.hardware import pwm_facts
from protocol.generator.model import PRIMITIVES, Spec
from protocol.generator.robots import Robot
from protocol.generator.wiring import PWM_ROLES, Part, Pin, Wiring

ROBOTS_PATH = "protocol/spec/robots.toml"


def _banner(spec: Spec, comment: str) -> str:
    return (
        f"{comment} DO NOT EDIT: generated from {ROBOTS_PATH} and {spec.path} by `{GENERATOR}`.\n"
        f"{comment} spec hash: 0x{spec.spec_hash:08X}\n"
    )


def emit(spec: Spec, robots: tuple[Robot, ...]) -> dict[str, str]:
    out = {"protocol/generated/profiles.py": _python(spec, robots), "docs/robots.md": _docs(spec, robots)}
    for r in robots:
        out[f"arduino/RoverLink/examples/{r.example}/robot_profile.h"] = _cpp(spec, r)
    return out


def _py_value(field_enum: str | None, value: object) -> str:
    if field_enum is not None:
        return f"{field_enum}.{value}"
    return num(value)  # type: ignore[arg-type]


def _python(spec: Spec, robots: tuple[Robot, ...]) -> str:
    o = [_banner(spec, "#")]
    o.append('"""Reference robot profiles: firmware defaults, kinematics and feedback mode, by name."""\n\n')
    o.append("from __future__ import annotations\n\nfrom dataclasses import dataclass\n\n")
    o.append("from protocol.generated.enums import Board, Capability, FeedbackMode, LightsMode, SafeState\n")
    o.append("from protocol.generated.messages import SetConfig, SetPid\n\n\n")
    o.extend(_py_class(*c) for c in _PY_CLASSES)
    o[-1] = o[-1].rstrip("\n") + "\n"
    o.append("\n\nPROFILES: dict[str, RobotProfile] = {\n")
    for r in robots:
        caps = " | ".join(f"Capability.{c}" for c in r.capabilities) or "Capability(0)"
        cfg = ", ".join(f"{f.name}={_py_value(f.enum.name if f.enum else None, v)}" for f, v in r.config)
        pid = ", ".join(f"{f.name}={num(v)}" for f, v in r.pid)
        o.append(f'    "{r.name}": RobotProfile(\n')
        o.append(f'        name="{r.name}",\n        example="{r.example}",\n        doc={r.doc!r},\n')
        o.append(f"        board=Board.{r.board},\n        capabilities={caps},\n")
        o.append(f'        kinematics="{r.kinematics}",\n        feedback_mode=FeedbackMode.{r.feedback_mode},\n')
        o.append(f"        lights_mode=LightsMode.{r.lights_mode},\n")
        o.append(f"        track_m={num(r.track_mm / 1000)},\n        wheelbase_m={num(r.wheelbase_mm / 1000)},\n")
        o.append(f"        wheel_diameter_m={num(r.value('wheel_diameter_um') / 1e6)},\n")
        o.append(f"        encoder_cpr={r.value('encoder_cpr')},\n")
        o.append(f"        config=SetConfig({cfg}),\n")
        o.append(f"        pid=SetPid(wheel=255, {pid}),\n")
        o.append(f"        wiring={_py_wiring(r.wiring)},\n    ),\n")
    o.append("}\n")
    o.append('"""Reference robots by profile name."""\n')
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
        "Which Arduino pin serves which part (robots.toml, [robots.wiring]).",
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


def _py_part(p: Part) -> str:
    pins = ", ".join(f'("{role}", {pin.number})' for role, pin in p.pins)
    return f'WiredPart("{p.kind}", ({pins},))'


def _py_wiring(w: Wiring) -> str:
    motors = "".join(f"{_py_part(p)}, " for p in w.motors)
    encoders = "".join(f"{_py_part(p)}, " for p in w.encoders)
    leds = "".join(f"{pin.number}, " for _, pin in w.leds)
    esc = w.esc.number if w.esc else None
    servo = w.servo.number if w.servo else None
    return (
        f"Wiring(\n            motors=({motors.rstrip()}),\n            encoders=({encoders.rstrip()}),\n"
        f"            esc_pin={esc},\n            servo_pin={servo},\n            led_pins=({leds.rstrip()}),\n"
        f"            entropy_pin={w.entropy.number},\n        )"
    )


def pin_constants(w: Wiring) -> list[tuple[str, str, str]]:
    """(C++ constant name, pin as written, what it serves) for every wired pin, in robots.toml order."""
    out: list[tuple[str, str, str]] = []
    names = w.channel_names()
    for i, motor in enumerate(w.motors):
        for role, pin in motor.pins:
            out.append((f"{names[i].upper()}_{role.upper()}", pin.label, f"{names[i]} motor, {motor.kind} {role}"))
    for i, enc in enumerate(w.encoders):
        for role, pin in enc.pins:
            out.append((f"{names[i].upper()}_ENC_{role.upper()}", pin.label, f"{names[i]} encoder, channel {role}"))
    for name, pin in w.leds:
        out.append((f"LED_{name.upper()}", pin.label, f"LED {name.replace('_', ' ')}"))
    if w.esc is not None:
        out.append(("ESC_PIN", w.esc.label, "ESC signal"))
    if w.servo is not None:
        out.append(("STEERING_PIN", w.servo.label, "steering servo signal"))
    out.append(("ENTROPY_PIN", w.entropy.label, "entropy, leave unconnected: its ADC noise seeds the boot_id"))
    return out


def _cpp_pins(w: Wiring, source: str) -> str:
    numbers = {p.label: p.number for p in _all_pins(w)}
    o = [f"// Wiring ({source}): Arduino pin numbers (A<n> as its number on this board).\n"]
    for name, label, what in pin_constants(w):
        analog = f" ({label})" if label.startswith("A") else ""
        o.append(f"static const uint8_t {name} = {numbers[label]};  // {what}{analog}\n")
    return "".join(o) + "\n"


def _all_pins(w: Wiring) -> list[Pin]:
    parts = [pin for p in (*w.motors, *w.encoders) for _, pin in p.pins]
    singles = [p for p in (w.esc, w.servo) if p is not None]
    return [*parts, *singles, *(pin for _, pin in w.leds), w.entropy]


def _cpp_value(field_enum: str | None, value: object, is_float: bool) -> str:
    if field_enum is not None:
        return f"roverlink::proto::{field_enum}::{value}"
    if is_float:
        return f"{float(value)!r}f"  # type: ignore[arg-type]
    return str(value)


def _cpp(spec: Spec, r: Robot) -> str:
    return profile_header(spec, r)


def profile_header(spec: Spec, r: Robot, source: str | None = None) -> str:
    """The example's robot_profile.h: from robots.toml (`source` None), or from the robot file at
    `source`, whose robot name the firmware then reports (IDENTITY robot_name) instead of the example's."""
    if source is None:
        o = [_banner(spec, "//")]
        o.append(f"// Defaults of the {r.example} example ({r.name}): {r.doc}\n")
        o.append("// Change them over the link (SET_CONFIG, SET_PID) and SAVE_CONFIG, or edit robots.toml.\n")
        name, wiring_from, checked = r.example, "robots.toml, [robots.wiring]", "robots.toml"
    else:
        o = [f"// DO NOT EDIT: generated from {source} by `roverlink firmware`; edit that file instead.\n"]
        o.append(f"// spec hash: 0x{spec.spec_hash:08X}\n")
        about = f": {r.doc}" if r.doc else ""
        o.append(f"// Defaults of {r.name} ({r.example} example){about}\n")
        o.append("// Change them over the link (SET_CONFIG, SET_PID) and SAVE_CONFIG, or edit the robot file.\n")
        name, wiring_from, checked = r.name, source, "the robot file"
    guard = f"ROVERLINK_EXAMPLE_{r.example.upper()}_PROFILE_H"
    o.append(f"#ifndef {guard}\n#define {guard}\n\n#include <RoverLink.h>\n\nnamespace robot_profile {{\n\n")
    o.append(f'static const char NAME[] = "{name}";\n')
    o.append(f"static const roverlink::proto::Board BOARD = roverlink::proto::Board::{r.board};\n")
    caps = " | ".join(f"roverlink::proto::Capability::{c}" for c in r.capabilities) or "0"
    o.append(f"static const uint16_t CAPABILITIES = {caps};\n")
    o.append(
        "static const roverlink::proto::FeedbackMode FEEDBACK_MODE = "
        f"roverlink::proto::FeedbackMode::{r.feedback_mode};\n"
        "static const roverlink::proto::LightsMode LIGHTS_MODE = "
        f"roverlink::proto::LightsMode::{r.lights_mode};  // turn signals at power-up\n\n"
    )
    o.append(_cpp_pins(r.wiring, wiring_from))
    o.append(_cpp_pwm(r))
    o.append(_cpp_defaults(r, checked))
    o.append(f"#endif  // {guard}\n")
    return "".join(o)


ULTRASONIC_HZ = 31373
"""What hal/avr/motors.h's pwm_ultrasonic() sets a timer to (prescaler 1, 8-bit phase correct)."""


def _cpp_pwm(r: Robot) -> str:
    """The motor PWM pins whose timer the sketch must set (every one whose driver needs another
    frequency than the core's, on whichever timer it is: hardware.toml's PWM tables)."""
    facts = pwm_facts()
    fast = []
    for motor in r.wiring.motors:
        for role, pin in motor.pins:
            if role not in PWM_ROLES:
                continue
            timer, hz = facts.timer_of(r.board, pin.number), facts.hz(r.board, pin.number, motor.kind)
            if timer is None or hz is None or hz == timer.hz[0]:
                continue  # no facts for the board, or the core's own frequency
            if hz != ULTRASONIC_HZ:
                raise ValueError(f"{r.name}: pin {pin.label} at {hz} Hz: the firmware sets {ULTRASONIC_HZ} Hz only")
            if pin.number not in fast:
                fast.append(pin.number)
    if not fast:
        return ""
    o = ["// Motor PWM pins whose driver runs above the core's frequency (protocol/spec/hardware.toml):\n"]
    o.append(f"// the sketch sets each one's timer to {ULTRASONIC_HZ} Hz (pwm_ultrasonic), whichever timer it is on.\n")
    o.append(f"static const uint8_t FAST_PWM_PINS[] = {{{', '.join(map(str, fast))}}};\n")
    o.append(f"static const uint8_t FAST_PWM_PIN_COUNT = {len(fast)};\n\n")
    return "".join(o)


def _cpp_defaults(r: Robot, checked: str) -> str:
    o = ["// The configuration as a SET_CONFIG payload in flash, unpacked when asked for: a static struct\n"]
    o.append("// would cost SRAM for the whole run on AVR, and code setting each field more flash than this.\n")
    o.append("// static: two profiles linked into one test program must not merge.\n")
    o.append("static const uint8_t DEFAULT_CONFIG[] ROVERLINK_PROGMEM = {\n")
    for f, v in r.config:
        number = next(e.value for e in f.enum.values if e.name == v) if f.enum else v
        data = struct.pack("<" + PRIMITIVES[f.prim][2], number)
        o.append(f"    {', '.join(f'0x{b:02X}' for b in data)},  // {f.name} = {v}\n")
    o.append("};\n")
    o.append(
        'static_assert(sizeof DEFAULT_CONFIG == roverlink::proto::SetConfig::PAYLOAD_SIZE, "a SET_CONFIG payload");\n\n'
    )
    o.append("static inline roverlink::proto::SetConfig default_config() {\n")
    o.append("    uint8_t payload[sizeof DEFAULT_CONFIG];\n")
    o.append("    for (uint8_t i = 0; i < sizeof payload; ++i) {\n")
    o.append("        payload[i] = ROVERLINK_READ_BYTE(DEFAULT_CONFIG + i);\n    }\n")
    o.append("    roverlink::proto::SetConfig c = roverlink::proto::SetConfig();\n")
    o.append(f"    roverlink::proto::unpack(payload, sizeof payload, c);  // valid: {checked} is checked\n")
    o.append("    return c;\n}\n\n")
    o.append("static inline roverlink::proto::SetPid default_pid() {\n    roverlink::proto::SetPid p;\n")
    o.append("    p.wheel = roverlink::proto::PID_ALL_WHEELS;\n")
    for f, v in r.pid:
        o.append(f"    p.{f.name} = {_cpp_value(None, v, True)};\n")
    o.append("    return p;\n}\n\n}  // namespace robot_profile\n\n")
    return "".join(o)


def _docs(spec: Spec, robots: tuple[Robot, ...]) -> str:
    o = [f"<!-- DO NOT EDIT: generated from {ROBOTS_PATH} and {spec.path} by `{GENERATOR}`. -->\n"]
    o.append(f"<!-- spec hash: 0x{spec.spec_hash:08X} -->\n\n# Reference robots\n\n")
    o.append("Each robot's defaults live once, in `protocol/spec/robots.toml`; the firmware example, the ")
    o.append("emulator profile and the SDK's kinematics are generated from it, and so is each robot's robot file ")
    o.append("(`protocol/robots/<name>.toml`).\n\n")
    o.append("To adapt one to your robot, copy its file with `roverlink robot new my_robot.toml --from <name>`, ")
    o.append(
        "change it, and run `roverlink robot check my_robot.toml` (every key: [robot-file.md](robot-file.md)).\n\n"
    )
    o.append("| | " + " | ".join(f"`{r.name}`" for r in robots) + " |\n|---|" + "---|" * len(robots) + "\n")
    rows: list[tuple[str, list[str]]] = [
        ("firmware example", [f"`{r.example}`" for r in robots]),
        ("board", [r.board for r in robots]),
        ("kinematics", [r.kinematics for r in robots]),
        ("feedback mode", [r.feedback_mode for r in robots]),
        ("capabilities", [", ".join(r.capabilities) for r in robots]),
        ("track (mm)", [num(r.track_mm) for r in robots]),
        ("wheelbase (mm)", [num(r.wheelbase_mm) for r in robots]),
    ]
    for f, _ in robots[0].config + robots[0].pid:
        unit = f" ({f.unit})" if f.unit else ""
        rows.append((f"`{f.name}`{unit}", [str(r.value(f.name)) for r in robots]))
    for label, values in rows:
        o.append(f"| {label} | " + " | ".join(values) + " |\n")
    o.append("\n")
    for r in robots:
        o.append(f"- **{r.name}**: {r.doc}\n")
    o.append("\n## Wiring\n\nArduino pins as the examples use them (`robot_profile.h` holds them as constants; the ")
    o.append("simavr backend maps them to the MCU's registers). Timers, interrupts and power: docs/firmware.md, ")
    o.append('"Boards, wiring and flashing".\n')
    for r in robots:
        o.append(f"\n### {r.example} (`{r.name}`, {r.board})\n\n| pin | serves | constant |\n|---|---|---|\n")
        for name, label, what in pin_constants(r.wiring):
            o.append(f"| {label} | {what} | `{name}` |\n")
    return "".join(o)
