"""Emit the reference robots as robot files (protocol/robots/<name>.toml): robots.toml's firmware
defaults and wiring, converted to the file's SI units, with sensors.toml's mounts and footprint.
Each key carries its unit and meaning from the robot file schema, so `roverlink robot new` can hand
out a commented copy."""

from __future__ import annotations

import json
from typing import Any

from protocol.generator.emit.common import GENERATOR
from protocol.generator.robots import Robot
from protocol.generator.wiring import Pin
from protocol.robotfile.schema import SECTIONS
from protocol.sensors import ROBOT_SENSORS, RobotSensors

SOURCES = "protocol/spec/robots.toml and protocol/spec/sensors.toml"


def _toml(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_toml(x)}" for k, x in v.items()) + " }"
    return str(v)


def _section(name: str, values: dict[str, Any]) -> list[str]:
    keys = {k.name: k for k in SECTIONS[name]}
    out = [f"\n[{name}]"] if name else []
    for key, value in values.items():
        spec = keys[key]
        unit = f"[{spec.unit}] " if spec.unit else ""
        text = f"{key} = {_toml(value)}"
        if isinstance(value, list) and value and isinstance(value[0], dict):
            text = f"{key} = [\n" + "".join(f"    {_toml(x)},\n" for x in value) + "]"
        out.append(f"{text}  # {unit}{spec.doc}" if "\n" not in text else f"# {unit}{spec.doc}\n{text}")
    return out


def _flags(bits: int, channels: int) -> list[bool]:
    return [bool(bits >> i & 1) for i in range(channels)]


def _drive(r: Robot, channels: int) -> list[str]:
    w, c = r.wiring, r.value
    drive: dict[str, Any] = {"kind": "differential" if r.kinematics == "diff" else "ackermann"}
    drive["driver"] = w.motors[0].kind if w.motors else "ESC+servo"
    if w.motors:
        drive["motors"] = [{role: _pin(p) for role, p in m.pins} for m in w.motors]
    drive["motor_invert"] = _flags(c("motor_invert"), channels)
    out = _section("drive", drive)
    if w.esc is not None:
        esc = {"pin": _pin(w.esc), "min_pulse_s": c("esc_min_us") / 1e6, "neutral_pulse_s": c("esc_neutral_us") / 1e6}
        out += _section("esc", esc | {"max_pulse_s": c("esc_max_us") / 1e6, "arm_s": c("esc_arm_ms") / 1000})
    if w.servo is not None:
        deg = {k: c(f"steering_{k}_cdeg") / 100 for k in ("center", "min", "max", "step")}
        pulses = {"min_pulse_s": c("servo_min_us") / 1e6, "max_pulse_s": c("servo_max_us") / 1e6}
        out += _section("steering", {"pin": _pin(w.servo)} | {f"{k}_deg": x for k, x in deg.items()} | pulses)
    return out


def _pin(p: Pin) -> int | str:
    return p.label if not p.label.isdigit() else p.number


def _sensors(body: RobotSensors) -> list[str]:
    out: list[str] = []
    for m in body.mounts:
        place = {"x_m": m.x_m, "y_m": m.y_m, "z_m": m.z_m, "yaw_deg": m.yaw_deg}
        out += _section(f"sensors.{m.name}", {"model": m.device} | place)
    return out


def render(r: Robot) -> str:
    c, w = r.value, r.wiring
    channels = 2 if r.kinematics == "diff" else 1
    o = [f"# DO NOT EDIT: generated from {SOURCES} by `{GENERATOR}`."]
    o.append(f"# Robot file of the reference robot {r.name} (the format: docs/robot-file.md).")
    o.append("# Start your own robot from it with `roverlink robot new my_robot.toml --from " + r.name + "`.\n")
    o += _section("", {"name": r.name, "description": r.doc, "board": r.board.lower(), "entropy_pin": _pin(w.entropy)})
    o += _drive(r, channels)
    enc: dict[str, Any] = {}
    if w.encoders:
        enc["pins"] = [{role: _pin(p) for role, p in e.pins} for e in w.encoders]
    enc |= {"counts_per_rev": c("encoder_cpr"), "decoding": "x4", "invert": _flags(c("encoder_invert"), channels)}
    o += _section("encoders", enc)
    geo = {"wheel_diameter_m": c("wheel_diameter_um") / 1e6, "track_m": r.track_mm / 1000}
    o += _section("geometry", geo | {"wheelbase_m": r.wheelbase_mm / 1000})
    limits = {"max_wheel_speed_m_s": c("max_wheel_speed_mm_s") / 1000, "accel_m_s2": c("accel_limit_mm_s2") / 1000}
    limits |= {"decel_m_s2": c("decel_limit_mm_s2") / 1000, "max_effort": c("max_effort_permille") / 1000}
    limits |= {"watchdog_s": c("watchdog_ms") / 1000, "safe_state": c("safe_state").lower()}
    o += _section("limits", limits)
    o += _section("pid", {k: float(c(k)) for k in ("kp", "ki", "kd", "kf", "ks")})
    feedback = {"mode": r.feedback_mode.lower(), "rate_hz": float(c("feedback_hz"))}
    o += _section("feedback", feedback | {"lockstep": "LOCKSTEP" in r.capabilities})
    if w.leds:
        lights: dict[str, object] = {name: _pin(p) for name, p in w.leds}
        o += _section("lights", lights | {"mode": r.lights_mode.lower()})
    body = ROBOT_SENSORS[r.name]
    o += _sensors(body)
    o += _section("footprint", {"radius_m": body.footprint_radius_m, "x_m": body.footprint_x_m})
    o.append("\n[calibration]")
    o.append("# Measured values (`roverlink calibrate` writes them); absent keys: the nominal ones above.")
    # The keys calibrate writes for this drive, without values: uncommented as they are, they are
    # refused, so no one drives on a figure nobody measured.
    o.append("# wheel_diameter_m = ...  # [m] measured wheel diameter")
    if w.servo is None:
        o.append("# track_m = ...  # [m] measured effective track")
    o.append("# counts_per_rev = ...  # [counts/rev] measured counts per wheel revolution")
    if w.servo is not None:
        o.append("# steering_trim_deg = ...  # [deg] added to steering.center_deg to drive straight")
    return "\n".join(o) + "\n"


def emit(robots: tuple[Robot, ...]) -> dict[str, str]:
    return {f"protocol/robots/{r.name}.toml": render(r) for r in robots}
