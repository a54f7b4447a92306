"""A reference robot's wiring (`[robots.wiring]` in robots.toml): which Arduino pin serves which part.

Checked here against the board (pin exists, not the serial pins, each pin used once) and against
the robot's capabilities (a DC motor per wheel channel or an ESC, a servo for steering, LEDs for
turn signals); the emitters turn it into the example's pin constants, the emulator profile's
wiring and the docs' wiring tables.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from protocol.generator.hardware import pwm_facts
from protocol.generator.loader import SpecError


@dataclass(frozen=True)
class BoardPins:
    digital: int
    """Arduino pin numbers 0..digital-1 (the analog pins included)."""
    first_analog: int
    """Pin number of A0."""
    analog: int
    """A0..A<analog-1>."""
    pwm: frozenset[int]
    """analogWrite() pins (a timer's compare output): motor drivers' speed inputs."""
    rc_timers: tuple[tuple[str, tuple[int, ...]], ...]
    """16-bit timers the RC pulse layer (hal/avr/rc_pulses.h) drives, and their channels' pins."""
    interrupts: frozenset[int]
    """External interrupt (INTn) pins."""
    pin_change: frozenset[int]
    """Pin-change interrupt pins (the variant's digitalPinToPCICR)."""


def _board(board: str, numbering: tuple[int, int, int], interrupts: set[int], pin_change: set[int]) -> BoardPins:
    """A board's pins (numbering: digital, first analog, analog count); its PWM pins and 16-bit
    timers from the hardware facts (hardware.toml)."""
    digital, first_analog, analog = numbering
    timers = [t for t in pwm_facts().timers if t.board == board]
    pwm = frozenset(p for t in timers for p in t.pins)
    rc = tuple((t.timer, t.pins) for t in timers if t.bits == 16)
    return BoardPins(digital, first_analog, analog, pwm, rc, frozenset(interrupts), frozenset(pin_change))


# The boards' Arduino pin numbering and interrupts (the Arduino core's variants): board facts.
# (Mega pin 13 is Timer1's channel C and Timer0's A; the core drives it from Timer0.)
BOARD_PINS = {
    "UNO": _board("UNO", (20, 14, 6), {2, 3}, set(range(20))),
    "MEGA2560": _board(
        "MEGA2560", (70, 54, 16), {2, 3, 18, 19, 20, 21}, {10, 11, 12, 13, 50, 51, 52, 53, *range(62, 70)}
    ),
}
SERIAL_PINS = (0, 1)  # USART0: the host link
DRIVERS: dict[str, tuple[str, ...]] = {
    "TB6612": ("pwm", "in1", "in2", "standby"),
    "L298N": ("pwm", "in1", "in2"),
    "BTS7960": ("rpwm", "lpwm", "r_en", "l_en"),
}
PWM_ROLES = ("pwm", "rpwm", "lpwm")
"""Driver inputs that take a PWM signal."""
ENCODER = ("a", "b")
SHARED_ROLES = {"TB6612": ("standby",)}
"""Roles whose pin the channels of one robot may share (TB6612: one STBY for both channels)."""


@dataclass(frozen=True)
class Pin:
    number: int
    label: str
    """As written in robots.toml ("6", "A8")."""


@dataclass(frozen=True)
class Part:
    """A DC motor driver channel (kind: its driver) or an encoder (kind "encoder"), and its pins."""

    kind: str
    pins: tuple[tuple[str, Pin], ...]  # (role, pin) in the order of DRIVERS[kind] / ENCODER


@dataclass(frozen=True)
class Wiring:
    motors: tuple[Part, ...]  # wheel-channel order
    encoders: tuple[Part, ...]  # wheel-channel order
    esc: Pin | None
    servo: Pin | None
    leds: tuple[tuple[str, Pin], ...]  # (Lights bit name, lower case, pin) in bit order
    entropy: Pin

    def channel_names(self) -> tuple[str, ...]:
        """Names of the wheel channels in generated code: left and right, or motor for one."""
        return ("left", "right") if max(len(self.motors), len(self.encoders)) == 2 else ("motor",)


def resolve_pin(value: Any, board: str) -> tuple[int | None, str]:
    """The pin number of `value` (9, "A0") on `board`, or None and why it is not a usable pin."""
    b = BOARD_PINS[board]
    if isinstance(value, str) and value.startswith("A") and value[1:].isdigit() and int(value[1:]) < b.analog:
        number = b.first_analog + int(value[1:])
    elif isinstance(value, int) and not isinstance(value, bool) and 0 <= value < b.digital:
        number = value
    else:
        return None, f"{value!r} is not a pin of the {board} (0..{b.digital - 1} or A0..A{b.analog - 1})"
    if number in SERIAL_PINS:
        return None, f"pin {number} is the serial port's (the host link)"
    return number, ""


def _names(pins: frozenset[int] | tuple[int, ...]) -> str:
    return ", ".join(str(p) for p in sorted(pins))


def pwm_problem(number: int, label: str, board: str, driver: str | None = None) -> str:
    """Why pin `number` cannot drive `driver`'s PWM input on `board` ("" if it can): a PWM pin
    whose timer can give a frequency in the driver's range (hardware.toml, [[pwm_drivers]] and
    [[pwm_timers]])."""
    pwm, facts = BOARD_PINS[board].pwm, pwm_facts()
    need = facts.driver(driver) if driver else None

    def able() -> str:  # the pins that would do, named only when one will not
        return _names(tuple(p for p in pwm if need is None or facts.hz(board, p, need.driver)))

    if number not in pwm:
        which = f"PWM pins whose timer can drive the {need.driver}" if need is not None else "PWM pins"
        return f"pin {label} has no PWM output on the {board} ({which}: {able()})"
    timer = facts.timer_of(board, number)
    if need is None or timer is None or facts.hz(board, number, need.driver) is not None:
        return ""
    why = f" ({timer.note})" if timer.note else ""
    gives = ", ".join(map(str, timer.hz))
    return (
        f"pin {label} is on {timer.timer} of the {board}, which gives {gives} Hz only{why}; "
        f"the {need.driver} needs {need.min_hz}..{need.max_hz} Hz, {need.why} "
        f"(PWM pins whose timer can: {able()})"
    )


def encoder_problem(number: int, label: str, board: str) -> str:
    """Why pin `number` cannot count encoder edges on `board` ("" if it can): the AVR encoder needs
    an external or a pin-change interrupt on both channels."""
    b = BOARD_PINS[board]
    if number in b.interrupts or number in b.pin_change:
        return ""
    return (
        f"pin {label} cannot interrupt on the {board} (encoder pins need an external interrupt: "
        f"{_names(b.interrupts)}, or a pin-change interrupt: {_names(b.pin_change)})"
    )


def rc_problem(pins: dict[str, tuple[int, str]], board: str) -> str:
    """Why the RC pins (role -> (number, label)) cannot all be pulsed by one 16-bit timer of `board`
    ("" if they can): the firmware's RC pulses come from a timer's compare channels, not software."""
    timers = BOARD_PINS[board].rc_timers
    numbers = {n for n, _ in pins.values()}
    if any(numbers <= set(channels) for _, channels in timers):
        return ""
    allowed = "; ".join(f"{name}: pins {_names(channels)}" for name, channels in timers)
    wired = ", ".join(f"{role} {label}" for role, (_, label) in pins.items())
    return f"{wired}: the ESC and servo pulses need the pins of one 16-bit timer ({allowed})"


class _Parser:
    def __init__(self, path: str, entry: str, board: str) -> None:
        self.path = path
        self.entry = entry
        self.board = BOARD_PINS[board]
        self.board_name = board
        self.used: dict[int, tuple[str, str | None]] = {}  # pin -> (where, shared role)

    def fail(self, where: str, problem: str) -> SpecError:
        return SpecError(self.path, f"{self.entry}.{where}", problem)

    def pin(self, value: Any, where: str) -> Pin:
        number, problem = resolve_pin(value, self.board_name)
        if number is None:
            raise self.fail(where, problem)
        return Pin(number, str(value))

    def check(self, where: str, problem: str) -> None:
        if problem:
            raise self.fail(where, problem)

    def claim(self, pin: Pin, where: str, share: str | None = None) -> None:
        """Each pin serves one part; `share` names a role several channels may share (TB6612 STBY)."""
        first = self.used.get(pin.number)
        if first is not None and (share is None or first[1] != share):
            raise self.fail(where, f"pin {pin.label} already serves {first[0]}")
        self.used.setdefault(pin.number, (where, share))

    def part(self, raw: Any, where: str, kind: str | None) -> Part:
        if not isinstance(raw, dict):
            raise self.fail(where, "expected a table")
        if kind is None:
            kind = raw.get("driver")
            if kind not in DRIVERS:
                raise self.fail(where, f"driver {kind!r} is not one of {', '.join(DRIVERS)}")
        roles = DRIVERS.get(kind, ENCODER)
        keys = set(roles) | ({"driver"} if kind in DRIVERS else set())
        if set(raw) != keys:
            raise self.fail(where, f"keys must be exactly: {', '.join(sorted(keys))}")
        pins = tuple((role, self.pin(raw[role], f"{where}.{role}")) for role in roles)
        for role, pin in pins:
            if role in PWM_ROLES:
                self.check(f"{where}.{role}", pwm_problem(pin.number, pin.label, self.board_name, kind))
            if kind == "encoder":
                self.check(f"{where}.{role}", encoder_problem(pin.number, pin.label, self.board_name))
        for role, pin in pins:
            if role == "l_en" and pin == dict(pins)["r_en"]:
                continue  # R_EN and L_EN of one BTS7960 may share a pin
            share = f"{kind}.{role}" if role in SHARED_ROLES.get(kind, ()) else None
            self.claim(pin, f"{where}.{role}", share)
        return Part(kind, pins)

    def parts(self, raw: Any, where: str, kind: str | None) -> tuple[Part, ...]:
        if not isinstance(raw, list):
            raise self.fail(where, "expected a list")
        return tuple(self.part(p, f"{where}[{i}]", kind) for i, p in enumerate(raw))


def parse(
    path: str, entry: str, table: Any, *, board: str, capabilities: tuple[str, ...], lights: tuple[str, ...]
) -> Wiring:
    """`lights`: the Lights bit names of the hardware contract, in bit order."""
    p = _Parser(path, entry, board)
    if not isinstance(table, dict):
        raise SpecError(path, entry, "expected a table")
    allowed = {"entropy", "motors", "encoders", "esc", "servo", "leds"}
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise SpecError(path, entry, f"unknown key(s): {', '.join(unknown)} (allowed: {', '.join(sorted(allowed))})")
    caps = set(capabilities)
    channels = 2 if "DIFF_DRIVE" in caps else 1
    wanted = {
        "motors": 0 if "ESC" in caps else channels,
        "encoders": channels if "ENCODERS" in caps else 0,
    }
    for key, count in wanted.items():
        have = len(table.get(key, []))
        if have != count:
            raise p.fail(key, f"{have} listed, the capabilities ask for {count} (one per wheel channel)")
    for key, cap in (("esc", "ESC"), ("servo", "STEERING_SERVO"), ("leds", "TURN_SIGNALS")):
        if (key in table) != (cap in caps):
            raise p.fail(key, f"needed exactly when the robot has the {cap} capability")
    entropy = p.pin(table.get("entropy"), "entropy")
    if entropy.number < p.board.first_analog:
        raise p.fail("entropy", f"{entropy.label} is not an analog pin (its ADC noise seeds the boot_id)")
    p.claim(entropy, "entropy")
    motors = p.parts(table.get("motors", []), "motors", None)
    encoders = p.parts(table.get("encoders", []), "encoders", "encoder")
    singles: dict[str, Pin | None] = dict.fromkeys(("esc", "servo"))
    for key in singles:
        if key in table:
            singles[key] = pin = p.pin(table[key], key)
            p.claim(pin, key)
    rc = {key: (pin.number, pin.label) for key, pin in singles.items() if pin is not None}
    if rc:
        p.check("esc" if "esc" in rc else "servo", rc_problem(rc, board))
    leds: list[tuple[str, Pin]] = []
    if "leds" in table:
        raw = table["leds"]
        names = [n.lower() for n in lights]
        if not isinstance(raw, dict) or set(raw) != set(names):
            raise p.fail("leds", f"one pin per Lights bit: {', '.join(names)}")
        for name in names:
            pin = p.pin(raw[name], f"leds.{name}")
            p.claim(pin, f"leds.{name}")
            leds.append((name, pin))
    return Wiring(motors, encoders, singles["esc"], singles["servo"], tuple(leds), entropy)
