"""A robot file's pins, checked with the generator's hardware rules (protocol/generator/wiring.py:
pin numbering, serial pins, PWM, interrupts, RC timers) so the reference robots and users' robots
obey one set; every problem is collected. The native board (the core built for the host) has no
pins to check beyond each serving one part."""

from __future__ import annotations

from typing import Any

from protocol.generated.profiles import WiredPart, Wiring
from protocol.generator import wiring as rules
from protocol.robotfile.reader import Reader
from protocol.robotfile.schema import LIGHTS

_Where = tuple[str, tuple[str | int, ...]]


def _name(where: _Where) -> str:
    out = where[0]
    for step in where[1]:
        out += f"[{step}]" if isinstance(step, int) else (f".{step}" if out else step)
    return out


class _Pins:
    def __init__(self, reader: Reader, board: str) -> None:
        self.r = reader
        self.board = {"uno": "UNO", "mega2560": "MEGA2560", "pico": "PICO"}.get(board)
        self.used: dict[int, tuple[str, str | None]] = {}

    def pin(self, value: Any, where: _Where, share: str | None = None, claim: bool = True) -> int | None:
        """The pin number of `value`, claimed for `where` (`share`: a role channels may share)."""
        if self.board is None:
            ok = isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= 255
            number, problem = (int(value), "") if ok else (None, f"{value!r} is not a pin number (0..255)")
        else:
            number, problem = rules.resolve_pin(value, self.board)
        if number is None:
            self.r.report(*where, f"= {value!r}: {problem}")
            return None
        first = self.used.get(number) if claim else None
        if first is not None and (share is None or first[1] != share):
            self.r.report(*where, f"= {value!r}: pin already serves {first[0]} (one function per pin)")
        if claim:
            self.used.setdefault(number, (_name(where), share))
        return number

    def rule(self, problem: str, where: _Where) -> None:
        if problem and self.board is not None:
            self.r.report(*where, problem)

    def part(self, raw: dict[str, Any], kind: str, roles: tuple[str, ...], where: _Where) -> WiredPart | None:
        section, path = where
        for name in raw:
            if name not in roles:
                self.r.unknown(section, f"{path[0]}[{path[1]}].{name}", list(roles), f"{kind} pin")
        pins: list[tuple[str, int]] = []
        for role in roles:
            at = (section, (*path, role))
            if role not in raw:
                self.r.report(*at, f"missing (a {kind} needs pins {', '.join(roles)})")
                continue
            same_pin = role == "l_en" and raw.get("r_en") == raw[role]  # one BTS7960's enables may share
            share = f"{kind}.{role}" if role in rules.SHARED_ROLES.get(kind, ()) else None
            number = self.pin(raw[role], at, share, claim=not same_pin)
            if number is None:
                continue
            label = str(raw[role])
            if self.board is not None and role in rules.PWM_ROLES:
                self.rule(rules.pwm_problem(number, label, self.board, kind), at)
            if self.board is not None and kind == "encoder":
                self.rule(rules.encoder_problem(number, label, self.board), at)
            pins.append((role, number))
        return WiredPart(kind, tuple(pins)) if len(pins) == len(roles) else None


def read(reader: Reader, v: dict[str, Any], channels: int) -> Wiring:
    """The Wiring of the file's pins (`v`: the reader's sections), every problem reported."""
    p = _Pins(reader, v["board"] or "native")
    drive, enc = v["drive"] or {}, v["encoders"] or {}
    # The Pico draws its boot_id noise from the ring oscillator: no pin is read or claimed for it.
    entropy = None if p.board == "PICO" else p.pin(v["entropy_pin"], ("", ("entropy_pin",)))
    if entropy is not None and p.board is not None and entropy < rules.BOARD_PINS[p.board].first_analog:
        reader.report(
            "", ("entropy_pin",), f"= {v['entropy_pin']!r} is not an analog pin (its noise seeds the boot_id)"
        )
    driver = drive.get("driver")
    motors: list[WiredPart | None] = []
    raw_motors = drive.get("motors") or []
    if driver in rules.DRIVERS:
        if len(raw_motors) != channels:
            reader.report("drive", ("motors",), f"{len(raw_motors)} listed, a {drive['kind']} robot has {channels}")
        motors = [p.part(m, driver, rules.DRIVERS[driver], ("drive", ("motors", i))) for i, m in enumerate(raw_motors)]
    elif raw_motors:
        reader.report("drive", ("motors",), f"only DC drivers ({', '.join(rules.DRIVERS)}) take motor pins")
    raw_enc = enc.get("pins") or []
    if raw_enc and len(raw_enc) != channels:
        reader.report("encoders", ("pins",), f"{len(raw_enc)} listed, a {drive.get('kind')} robot has {channels}")
    encoders = [p.part(e, "encoder", rules.ENCODER, ("encoders", ("pins", i))) for i, e in enumerate(raw_enc)]
    rc: dict[str, tuple[int, str]] = {}
    singles: dict[str, int | None] = {}
    for section in ("esc", "steering"):
        table = v[section]
        singles[section] = None if table is None else p.pin(table["pin"], (section, ("pin",)))
        if singles[section] is not None and table is not None:
            rc[section] = (singles[section] or 0, str(table["pin"]))
    if rc and p.board is not None:
        timed = {n for _, channels in rules.BOARD_PINS[p.board].rc_timers for n in channels}
        first = next((k for k, (n, _) in rc.items() if n not in timed), list(rc)[-1])  # the pin off every timer
        p.rule(
            rules.rc_problem({"esc" if k == "esc" else "servo": x for k, x in rc.items()}, p.board), (first, ("pin",))
        )
        motor_pwm = {n for m in motors if m is not None for role, n in m.pins if role in rules.PWM_ROLES}
        for section, (number, label) in rc.items():
            p.rule(rules.slice_problem(number, label, p.board, motor_pwm), (section, ("pin",)))
    lights = v["lights"]
    leds = [] if lights is None else [p.pin(lights[n], ("lights", (n,))) for n in LIGHTS]
    return Wiring(
        motors=tuple(m for m in motors if m is not None),
        encoders=tuple(e for e in encoders if e is not None),
        esc_pin=singles["esc"],
        servo_pin=singles["steering"],
        led_pins=tuple(x for x in leds if x is not None),
        entropy_pin=entropy if entropy is not None else 0,
    )
