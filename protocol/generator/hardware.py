"""The hardware contract (protocol/spec/hardware.toml): the enums the firmware core hands to a board,
and the motor PWM facts: each driver's frequency, each board's PWM pins by timer."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from protocol.generator.loader import SpecError, _Loader
from protocol.generator.model import Enum, Spec
from protocol.toml import tomllib


@dataclass(frozen=True)
class PwmDriver:
    """The PWM frequencies a DC driver's input needs, and why those."""

    driver: str
    min_hz: int
    max_hz: int
    why: str


@dataclass(frozen=True)
class PwmTimer:
    """A board's timer, the analogWrite() pins it drives and the frequencies it can give there."""

    board: str
    timer: str
    bits: int
    """The counter's width: 16-bit timers can also pulse RC servos and ESCs."""
    pins: tuple[int, ...]
    """Its compare outputs' pins, channel A first."""
    hz: tuple[int, ...]
    note: str = ""
    """Why it gives only those (empty: any the table lists)."""


@dataclass(frozen=True)
class Pwm:
    drivers: tuple[PwmDriver, ...]
    timers: tuple[PwmTimer, ...]

    def driver(self, name: str) -> PwmDriver | None:
        return next((d for d in self.drivers if d.driver == name), None)

    def hz(self, board: str, pin: int, driver: str) -> int | None:
        """The frequency `pin` runs `driver` at: the first its timer gives in the driver's range
        (None: none does, or no facts for the pin or the driver)."""
        need, timer = self.driver(driver), self.timer_of(board, pin)
        if need is None or timer is None:
            return None
        return next((hz for hz in timer.hz if need.min_hz <= hz <= need.max_hz), None)

    def timer_of(self, board: str, pin: int) -> PwmTimer | None:
        return next((t for t in self.timers if t.board == board and pin in t.pins), None)


@dataclass(frozen=True)
class Hardware:
    path: str  # repository-relative, for DO NOT EDIT lines
    enums: tuple[Enum, ...]
    pwm: Pwm


def parse(text: str, path: str, spec: Spec) -> Hardware:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(path, "", f"not valid TOML: {exc}") from None
    loader = _Loader(path, data)
    top = loader.keys(data, "top level", {"enums"}, {"pwm_drivers", "pwm_timers", "pico_pinout"})
    enums = loader.enums(top["enums"])
    # The emulator and the tests import these next to the spec's enums: one name, one meaning.
    taken = {e.name for e in spec.enums} | {m.class_name for m in spec.messages}
    for i, e in enumerate(enums):
        if e.name in taken:
            raise SpecError(path, f"enums[{i}] {e.name}", f"{e.name!r} is already a name in {spec.path}")
    return Hardware(path, enums, _pwm(loader, top))


def _pwm(loader: _Loader, top: dict[str, Any]) -> Pwm:
    drivers = []
    for i, raw in enumerate(top.get("pwm_drivers", [])):
        entry = f"pwm_drivers[{i}]"
        t = loader.keys(raw, entry, {"driver", "min_hz", "max_hz", "why"}, set())
        lo, hi = (loader.typed(t[k], int, entry, k) for k in ("min_hz", "max_hz"))
        drivers.append(PwmDriver(loader.typed(t["driver"], str, entry, "driver"), lo, hi, t["why"]))
    timers, seen = [], set()
    for i, raw in enumerate(top.get("pwm_timers", [])):
        entry = f"pwm_timers[{i}]"
        t = loader.keys(raw, entry, {"board", "timer", "bits", "pins", "hz"}, {"note"})
        bits = loader.typed(t["bits"], int, entry, "bits")
        if bits not in (8, 16):
            raise SpecError(loader.path, f"{entry}.bits", f"{bits} is not a timer width (8 or 16)")
        pins = tuple(loader.typed(p, int, entry, "pins") for p in t["pins"])
        for pin in pins:  # a pin's PWM comes from one timer (the core's digitalPinToTimer)
            if (t["board"], pin) in seen:
                raise SpecError(loader.path, entry, f"pin {pin} of {t['board']} is already another timer's")
            seen.add((t["board"], pin))
        hz = tuple(loader.typed(h, int, entry, "hz") for h in t["hz"])
        timers.append(PwmTimer(t["board"], t["timer"], bits, pins, hz, t.get("note", "")))
    return Pwm(tuple(drivers), tuple(timers))


_OWN = Path(__file__).resolve().parents[1] / "spec" / "hardware.toml"


@cache
def pwm_facts() -> Pwm:
    """The motor PWM facts of the hardware.toml beside the spec (for checks outside a generate run)."""
    text = _OWN.read_text(encoding="utf-8")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(str(_OWN), "", f"not valid TOML: {exc}") from None
    loader = _Loader(str(_OWN), data)
    return _pwm(loader, loader.keys(data, "top level", {"enums"}, {"pwm_drivers", "pwm_timers", "pico_pinout"}))


_Pins = tuple[tuple[str, int], ...]


@dataclass(frozen=True)
class PinOut:
    """The pins a drive is wired to on a board (hardware.toml, [[pico_pinout]]), in the robot
    file's terms; the robot-file reader checks them as it checks any file's."""

    driver: str
    motors: tuple[_Pins, ...] = ()
    encoders: tuple[_Pins, ...] = ()
    esc: int | None = None
    steering: int | None = None
    lights: tuple[int, ...] = ()


@cache
def pico_pinout() -> dict[str, PinOut]:
    """The Pico pinout of each driver, by driver name."""
    data = tomllib.loads(_OWN.read_text(encoding="utf-8"))
    loader = _Loader(str(_OWN), data)
    out: dict[str, PinOut] = {}
    for i, raw in enumerate(data.get("pico_pinout", [])):
        entry = f"pico_pinout[{i}]"
        t = loader.keys(raw, entry, {"driver", "encoders", "lights"}, {"motors", "esc", "steering"})

        def parts(key: str, t: dict[str, Any] = t, entry: str = entry) -> tuple[_Pins, ...]:
            return tuple(
                tuple((role, loader.typed(pin, int, entry, key)) for role, pin in part.items())
                for part in t.get(key, [])
            )

        single = {k: loader.typed(t[k], int, entry, k) if k in t else None for k in ("esc", "steering")}
        lights = tuple(loader.typed(p, int, entry, "lights") for p in t["lights"])
        driver = loader.typed(t["driver"], str, entry, "driver")
        out[driver] = PinOut(driver, parts("motors"), parts("encoders"), single["esc"], single["steering"], lights)
    return out


def load(path: Path, root: Path, spec: Spec) -> Hardware:
    return parse(path.read_text(encoding="utf-8"), path.resolve().relative_to(root.resolve()).as_posix(), spec)
