"""The fault specification: a small grammar shared by `roverlink emulate --faults` and the API.

    spec   := item ("," item)*
    item   := NAME ["." DIR] ["=" VALUE] ["@" TIME ["-" TIME]]
    DIR    := "h2m" (host to MCU) | "m2h" (MCU to host); both directions when left out
    TIME   := seconds of virtual time since the emulator started: "2", "2.5", "2.5s" or "2500ms"

Without "@" an item holds from the start; with "@T" it happens (or starts) at T; with "@T1-T2" it
holds from T1 until T2, when it is undone.

| item | VALUE | meaning |
|---|---|---|
| bitflip[.DIR]=P | 0..1 | each data bit flips with probability P |
| drop[.DIR]=P | 0..1 | each byte is lost with probability P |
| insert[.DIR]=P | 0..1 | a random byte follows each byte with probability P |
| noise[.DIR][=BER]@T1-T2 | 0..0.5 (0.02) | noise burst: bit error rate BER and random bytes |
| cut[.DIR]@T[-T2] | | link cut (restored at T2) |
| reset@T | | MCU reset (reset pin: bootloader, then a new boot) |
| dtr@T | | DTR reset, as when a serial program opens the port |
| brownout[=MS]@T | ms (50) | supply dip: MCU held in reset MS ms, ESC loses its calibration |
| stall=W@T[-T2] | wheel | wheel W jammed (released at T2) |
| encoder=W@T[-T2] | wheel | encoder W disconnected (reconnected at T2) |
| eeprom@T[-T2] | | EEPROM writes fail (SAVE_CONFIG answers EEPROM_ERROR) |
| traction=MU[@T[-T2]] | >= 0, inf | tyre friction coefficient (low values make the wheels slip) |

Example: "bitflip=1e-4,drop=1e-4,insert=1e-4,cut@2.0-3.5,reset@5.0,stall=0@4.0".
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from emulator.errors import FaultSpecError

RATE_KINDS = ("bitflip", "drop", "insert")
WINDOW_KINDS = ("cut", "stall", "encoder", "eeprom", "traction", *RATE_KINDS)
"""Items that can hold for a window (@T1-T2)."""
EVENT_KINDS = ("noise", "cut", "reset", "dtr", "brownout", "stall", "encoder", "eeprom")
KINDS = (*RATE_KINDS, "traction", "noise", "cut", "reset", "dtr", "brownout", "stall", "encoder", "eeprom")
DIRECTIONS = ("h2m", "m2h")
_DIRECTIONAL = (*RATE_KINDS, "noise", "cut")
_NEEDS_VALUE = (*RATE_KINDS, "traction", "stall", "encoder")
_NEEDS_TIME = ("noise", "cut", "reset", "dtr", "brownout", "stall", "encoder", "eeprom")
_NO_VALUE = ("cut", "reset", "dtr", "eeprom")
_ITEM = re.compile(r"^(?P<name>[a-z0-9]+)(?:\.(?P<dir>[a-z0-9]+))?(?:=(?P<value>[^@]*))?(?:@(?P<when>.*))?$")


@dataclass(frozen=True, slots=True)
class FaultItem:
    kind: str
    value: float | None
    direction: str | None
    """"h2m", "m2h" or None (both)."""
    start_us: int | None
    """None: from the start (a standing rate or setting)."""
    end_us: int | None
    token: str


@dataclass(frozen=True, slots=True)
class FaultSpec:
    items: tuple[FaultItem, ...] = ()

    def __bool__(self) -> bool:
        return bool(self.items)


def parse_time(text: str, token: str) -> int:
    """'2', '2.5s' or '2500ms' as integer microseconds."""
    t = text.strip()
    scale = 1_000_000
    if t.endswith("ms"):
        t, scale = t[:-2], 1000
    elif t.endswith("s"):
        t = t[:-1]
    try:
        value = float(t)
    except ValueError:
        raise FaultSpecError(token, f"time {text!r} is not a number of seconds (e.g. 2.5, 2.5s or 2500ms)") from None
    if not (math.isfinite(value) and value >= 0):
        raise FaultSpecError(token, f"time {text!r} must be >= 0")
    return round(value * scale)


def _number(text: str, token: str, what: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise FaultSpecError(token, f"{what} {text!r} is not a number") from None


def parse_item(token: str) -> FaultItem:
    m = _ITEM.match(token.strip())
    if m is None:
        raise FaultSpecError(token, "expected NAME[.DIR][=VALUE][@TIME[-TIME]]")
    name, direction, value_text, when = m.group("name", "dir", "value", "when")
    if name not in KINDS:
        raise FaultSpecError(token, f"unknown fault {name!r}; known: {', '.join(KINDS)}")
    if direction is not None:
        if name not in _DIRECTIONAL:
            raise FaultSpecError(token, f"{name} has no direction (only {', '.join(_DIRECTIONAL)} do)")
        if direction not in DIRECTIONS:
            raise FaultSpecError(token, f"direction {direction!r} must be one of {', '.join(DIRECTIONS)}")
    value: float | None = None
    if value_text is not None:
        if name in _NO_VALUE:
            raise FaultSpecError(token, f"{name} takes no value")
        value = _number(value_text, token, "value")
        _check_value(name, value, token)
    elif name in _NEEDS_VALUE:
        raise FaultSpecError(token, f"{name} needs a value: {name}=VALUE")
    start: int | None = None
    end: int | None = None
    if when is not None:
        first, dash, second = when.partition("-")
        start = parse_time(first, token)
        if dash:
            if name not in (*WINDOW_KINDS, "noise"):
                raise FaultSpecError(token, f"{name} happens at one time, not over a window")
            end = parse_time(second, token)
            if end <= start:
                raise FaultSpecError(token, f"window end {second!r} must be after its start {first!r}")
    elif name in _NEEDS_TIME:
        raise FaultSpecError(token, f"{name} needs a time: {name}@T")
    if name == "noise" and end is None:
        raise FaultSpecError(token, "noise needs a window: noise@T1-T2")
    return FaultItem(name, value, direction, start, end, token.strip())


def _check_value(name: str, value: float, token: str) -> None:
    if name in RATE_KINDS and not 0.0 <= value <= 1.0:
        raise FaultSpecError(token, f"{name} is a probability: 0..1, got {value}")
    if name == "noise" and not 0.0 < value <= 0.5:
        raise FaultSpecError(token, f"noise bit error rate must be in (0, 0.5], got {value}")
    if name == "traction" and not (value >= 0 and not math.isnan(value)):
        raise FaultSpecError(token, f"traction is a friction coefficient >= 0 (or inf), got {value}")
    if name == "brownout" and not 0 < value <= 60_000:
        raise FaultSpecError(token, f"brownout duration is 1..60000 ms, got {value}")
    if name in ("stall", "encoder") and not (value.is_integer() and 0 <= value <= 1):
        raise FaultSpecError(token, f"{name} needs a wheel index 0..1, got {value}")


def parse_faults(spec: str | None) -> FaultSpec:
    """Parse a comma-separated fault spec (empty or None: no faults)."""
    if spec is None or not spec.strip():
        return FaultSpec()
    return FaultSpec(tuple(parse_item(token) for token in spec.split(",") if token.strip()))
