"""The boards' pin rules a robot file's wiring is checked with (protocol/robotfile/pins.py): which
pins each board has, which are the serial port's, which give PWM at a driver's frequency, which
interrupt, and which timer pulses the ESC and the servo. Facts of the hardware, the same for every
robot (the timers' frequencies: protocol/spec/hardware.toml)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from protocol.generator.hardware import pwm_facts


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
    absent: frozenset[int] = frozenset()
    """Numbers inside 0..digital-1 the board's header does not bring out."""
    any_rc_pin: bool = False
    """The ESC and servo may be on any PWM pins whose timer drives no motor (the Pico's slices),
    not only on the channels of one 16-bit timer (the AVR's rc_pulses.h)."""


def _board(
    board: str,
    numbering: tuple[int, int, int],
    interrupts: set[int],
    pin_change: set[int],
    absent: set[int] | None = None,
) -> BoardPins:
    """A board's pins (numbering: digital, first analog, analog count); its PWM pins and 16-bit
    timers from the hardware facts (hardware.toml)."""
    digital, first_analog, analog = numbering
    timers = [t for t in pwm_facts().timers if t.board == board]
    pwm = frozenset(p for t in timers for p in t.pins)
    rc = tuple((t.timer, t.pins) for t in timers if t.bits == 16)
    out = frozenset(absent or ())
    return BoardPins(
        digital, first_analog, analog, pwm, rc, frozenset(interrupts), frozenset(pin_change), out, board == "PICO"
    )


# The boards' Arduino pin numbering and interrupts (the Arduino core's variants): board facts.
# (Mega pin 13 is Timer1's channel C and Timer0's A; the core drives it from Timer0.)
BOARD_PINS = {
    "UNO": _board("UNO", (20, 14, 6), {2, 3}, set(range(20))),
    "MEGA2560": _board(
        "MEGA2560", (70, 54, 16), {2, 3, 18, 19, 20, 21}, {10, 11, 12, 13, 50, 51, 52, 53, *range(62, 70)}
    ),
    # The Pico: GP0..GP28 (A0..A2 = GP26..GP28, the ADC's), every pin's edges interrupt (IO_BANK0);
    # GP23, GP24 and GP25 are the board's own (regulator mode, VBUS sense, its LED): not on the header.
    "PICO": _board("PICO", (29, 26, 3), set(range(29)) - {23, 24, 25}, set(), {23, 24, 25}),
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


def resolve_pin(value: Any, board: str) -> tuple[int | None, str]:
    """The pin number of `value` (9, "A0") on `board`, or None and why it is not a usable pin."""
    b = BOARD_PINS[board]
    if isinstance(value, str) and value.startswith("A") and value[1:].isdigit() and int(value[1:]) < b.analog:
        number = b.first_analog + int(value[1:])
    elif isinstance(value, int) and not isinstance(value, bool) and 0 <= value < b.digital:
        number = value
    else:
        return None, f"{value!r} is not a pin of the {board} (0..{b.digital - 1} or A0..A{b.analog - 1})"
    if number in b.absent:
        return None, f"pin {number} is not on the {board}'s header (its pins: {_ranges(b)})"
    if number in SERIAL_PINS:
        return None, f"pin {number} is the serial port's (the host link)"
    return number, ""


def _names(pins: frozenset[int] | tuple[int, ...]) -> str:
    return ", ".join(str(p) for p in sorted(pins))


def _ranges(b: BoardPins) -> str:
    """The board's pin numbers as runs: 0..22, 26..28."""
    runs: list[list[int]] = []
    for n in (n for n in range(b.digital) if n not in b.absent):
        if runs and runs[-1][-1] == n - 1:
            runs[-1].append(n)
        else:
            runs.append([n])
    return ", ".join(f"{r[0]}..{r[-1]}" if len(r) > 1 else str(r[0]) for r in runs)


def pwm_problem(number: int, label: str, board: str, driver: str | None = None) -> str:
    """Why pin `number` cannot drive `driver`'s PWM input on `board` ("" if it can): a PWM pin
    whose timer can give a frequency in the driver's range (hardware.toml, [[pwm_drivers]] and
    [[pwm_timers]])."""
    pwm, facts = BOARD_PINS[board].pwm, pwm_facts()
    need = facts.driver(driver) if driver else None

    def able() -> str:  # the pins that would do (on the header, not the host link's), named only when one will not
        usable = (p for p in pwm if p not in SERIAL_PINS and p not in BOARD_PINS[board].absent)
        return _names(tuple(p for p in usable if need is None or facts.hz(board, p, need.driver)))

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
    if BOARD_PINS[board].any_rc_pin:
        return ""  # any slice pulses them: slice_problem() keeps them off the motors' slices
    if any(numbers <= set(channels) for _, channels in timers):
        return ""
    allowed = "; ".join(f"{name}: pins {_names(channels)}" for name, channels in timers)
    wired = ", ".join(f"{role} {label}" for role, (_, label) in pins.items())
    return f"{wired}: the ESC and servo pulses need the pins of one 16-bit timer ({allowed})"


def slice_problem(number: int, label: str, board: str, motor_pwm: set[int]) -> str:
    """Why RC pin `number` cannot be pulsed at 50 Hz on `board` ("" if it can): on a board whose
    every timer can pulse (the Pico), its timer must drive no motor PWM pin (`motor_pwm`), which
    runs at the driver's frequency."""
    facts = pwm_facts()
    timer = facts.timer_of(board, number)
    if timer is None or not BOARD_PINS[board].any_rc_pin:
        return ""
    shared = sorted(p for p in motor_pwm if p in timer.pins)
    if not shared:
        return ""
    return (
        f"pin {label} is on {timer.timer} of the {board}, which runs motor PWM pin "
        f"{', '.join(map(str, shared))} at the driver's frequency; the ESC and servo pulses need a slice "
        f"of their own at 50 Hz"
    )
