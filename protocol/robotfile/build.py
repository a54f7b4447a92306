"""From a robot file's checked sections to a RobotFile: the checks that span keys (drive and
driver, which sections a drive needs, ordered limits, sensor models, the footprint's form)."""

from __future__ import annotations

from typing import Any

from protocol.robotfile import model, pins
from protocol.robotfile.reader import EMULATOR_PARTS, Reader
from protocol.sensors import DEVICES


def _need(r: Reader, v: dict[str, Any], section: str, wanted: bool, why: str) -> None:
    if wanted and v[section] is None:
        r.report("", (), f"missing section [{section}] ({why})")
    elif not wanted and v[section] is not None:
        r.report(section, (), f"[{section}] is only for {why}")


def _drive(r: Reader, v: dict[str, Any]) -> int:
    """Check the drive against its driver and sections; the number of wheel channels."""
    drive = v["drive"]
    if drive is None:
        r.report("", (), "missing section [drive]")
        return 1
    kind, driver = drive["kind"], drive["driver"]
    if kind == "ackermann" and driver not in (None, "ESC+servo"):
        r.report("drive", ("driver",), f"= {driver!r}: an ackermann robot drives through ESC+servo")
    if kind == "differential" and driver == "ESC+servo":
        r.report("drive", ("driver",), "= 'ESC+servo': a differential robot needs a DC driver per wheel")
    car = kind == "ackermann"
    _need(r, v, "esc", car, "an ackermann robot: its ESC")
    _need(r, v, "steering", car, "an ackermann robot: its steering servo")
    channels = 1 if car else 2
    for section, key in (("drive", "motor_invert"), ("encoders", "invert")):
        flags = (v[section] or {}).get(key)
        if flags is not None and len(flags) != channels:
            r.report(section, (key,), f"= {list(flags)!r}: one flag per wheel channel ({channels})")
    if car and (v["geometry"] or {}).get("wheelbase_m") == 0.0:
        r.report("geometry", ("wheelbase_m",), "= 0.0: an ackermann robot needs its wheelbase (> 0 m)")
    return channels


def _pid(r: Reader, table: dict[str, Any] | None, channels: int) -> model.Pid:
    """The gains; a key given as a list needs one gain per wheel channel."""
    v = table or {"kp": 1.0, "ki": 0.0, "kd": 0.0, "kf": 0.0, "ks": 0.0}
    wheels: list[list[float]] = [[] for _ in range(channels)]
    for name in model.GAIN_NAMES:
        value = v[name]
        if isinstance(value, tuple) and len(value) != channels:
            r.report("pid", (name,), f"= {list(value)!r}: one gain per wheel channel ({channels}), or one number")
            value = value[0]
        for w in range(channels):
            wheels[w].append(value[w] if isinstance(value, tuple) else value)
    per_wheel = tuple((g[0], g[1], g[2], g[3], g[4]) for g in wheels)
    return model.Pid(*per_wheel[0], per_wheel=per_wheel)


def _ordered(r: Reader, section: str, table: dict[str, Any] | None, keys: tuple[str, ...]) -> None:
    if table is None or any(table[k] is None for k in keys):
        return
    values = [table[k] for k in keys]
    if values != sorted(values):
        shown = ", ".join(f"{k} = {table[k]:g}" for k in keys)
        r.report(section, (keys[0],), f"{shown}: must be in the order {' <= '.join(keys)}")


def _sensors(r: Reader, v: dict[str, Any]) -> None:
    for kind in ("lidar", "imu", "camera"):
        table = v[f"sensors.{kind}"]
        if table is None or table["model"] is None:
            continue
        found = DEVICES.get(table["model"])
        if found is None or found.kind != kind:
            models = ", ".join(n for n, d in DEVICES.items() if d.kind == kind)
            r.report(f"sensors.{kind}", ("model",), f"= {table['model']!r}: not a {kind} model (one of {models})")


def _footprint(r: Reader, v: dict[str, Any]) -> model.Footprint:
    f = v["footprint"]
    if f is None:
        r.report("", (), "missing section [footprint] (radius_m, length_m + width_m, or polygon_m)")
        return model.Footprint(0.1, None, None, None, 0.0)
    forms = [f["radius_m"] is not None, f["length_m"] is not None or f["width_m"] is not None]
    forms.append(f["polygon_m"] is not None)
    if sum(forms) != 1 or (forms[1] and None in (f["length_m"], f["width_m"])):
        r.report("footprint", (), "give exactly one of: radius_m; length_m and width_m; polygon_m")
    return model.Footprint(**f)


def _serial(table: dict[str, Any] | None) -> model.SerialSensor | None:
    return None if table is None else model.SerialSensor(**table)


def _values(table: dict[str, Any] | None) -> model.Values | None:
    return None if table is None else tuple((k, x) for k, x in table.items() if x is not None)


def _example(r: Reader, table: dict[str, Any] | None) -> str:
    example = str((table or {}).get("example") or "")
    if example and not example.isidentifier():
        why = "an example sketch's name (a C++ identifier: DiffDriveTB6612)"
        r.report("firmware", ("example",), f"= {example!r}: {why}")
    return example


def robot(r: Reader, data: dict[str, Any]) -> model.RobotFile:
    """The RobotFile (meaningful only when `r` gathered no problems)."""
    v = r.top(data)
    channels = _drive(r, v)
    for section in ("encoders", "geometry", "limits"):
        if v[section] is None:
            r.report("", (), f"missing section [{section}]")
    _ordered(r, "esc", v["esc"], ("min_pulse_s", "neutral_pulse_s", "max_pulse_s"))
    _ordered(r, "steering", v["steering"], ("min_deg", "center_deg", "max_deg"))
    _ordered(r, "steering", v["steering"], ("min_pulse_s", "max_pulse_s"))
    feedback = v["feedback"] or {"mode": "stream", "rate_hz": 50.0, "lockstep": False}
    if feedback["mode"] == "lockstep" and not feedback["lockstep"]:
        r.report("feedback", ("mode",), "= 'lockstep' needs lockstep = true (the firmware must offer it)")
    _sensors(r, v)
    wiring = pins.read(r, v, channels)
    drive, enc, geo, lim = v["drive"] or {}, v["encoders"] or {}, v["geometry"] or {}, v["limits"] or {}
    no_flags = (False,) * channels
    return model.RobotFile(
        path=r.path,
        name=v["name"] or "",
        description=v["description"] or "",
        board=v["board"] or "native",
        drive=model.Drive(drive.get("kind") or "", drive.get("driver") or "", drive.get("motor_invert") or no_flags),
        esc=None if v["esc"] is None else model.Esc(**{k: x for k, x in v["esc"].items() if k != "pin"}),
        steering=None
        if v["steering"] is None
        else model.Steering(**{k: x for k, x in v["steering"].items() if k != "pin"}),
        encoders=model.Encoders(
            enc.get("counts_per_rev") or 1, enc.get("decoding") or "x4", enc.get("invert") or no_flags
        ),
        geometry=model.Geometry(**geo) if geo else model.Geometry(0.0, 0.0, 0.0, 1.0),
        limits=model.Limits(**lim) if lim else model.Limits(0.0, 0.0, 0.0, 0.0, 0.0, "brake"),
        pid=_pid(r, v["pid"], channels),
        feedback=model.Feedback(**feedback),
        wiring=wiring,
        lights=(v["lights"] or {}).get("mode") or "auto",
        lidar=_serial(v["sensors.lidar"]),
        imu=_serial(v["sensors.imu"]),
        camera=None if v["sensors.camera"] is None else model.Camera(**v["sensors.camera"]),
        footprint=_footprint(r, v),
        calibration=model.Calibration(**(v["calibration"] or {})),
        example=_example(r, v["firmware"]),
        emulator=model.Emulator(*(_values(v[f"emulator.{part}"]) for part in EMULATOR_PARTS)),
    )
