"""How an emulated robot is really built, where that differs from what its board's configuration says.

A real robot rarely matches its firmware's defaults: an encoder cable is swapped, the gearbox is
not the one on the label, the tyres are worn, the wheels sit wider apart than the drawing says.
`Physical` describes such a robot; the plant is built from it while the firmware keeps the
profile's configuration, so the board believes numbers the hardware does not obey. That is what
`roverlink calibrate` finds and fixes.

    emu://diffdrive-tb6612?physical=miscalibrated           the issue's board: see MISCALIBRATED
    emu://picar?encoder_flip=1&cpr_scale=1.07&steering_trim_deg=3

Each factor scales the true value against the configured one (true = configured * scale); a flip
mask's bit i says that wheel i's motor or encoder is mounted the other way from what the
configuration's motor_invert / encoder_invert believe.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from emulator.errors import EmulatorValueError


@dataclass(frozen=True, slots=True)
class Physical:
    cpr_scale: float = 1.0
    """True encoder counts per wheel revolution over the configured encoder_cpr."""
    wheel_scale: float = 1.0
    """True wheel diameter over the configured wheel_diameter_um."""
    track_scale: float = 1.0
    """True track width over the profile's (differential drive)."""
    motor_flip: int = 0
    """Bit i: wheel i's motor turns the other way than the configuration's motor_invert believes."""
    encoder_flip: int = 0
    """Bit i: wheel i's encoder counts the other way than the configuration's encoder_invert believes."""
    steering_trim_deg: float = 0.0
    """Servo angle, past the configured centre, at which the front wheels really point straight."""
    steering_ratio: float = 1.0
    """Front-wheel angle per servo-horn angle (the linkage)."""

    def __post_init__(self) -> None:
        for name, lo, hi in (
            ("cpr_scale", 0.5, 2.0),
            ("wheel_scale", 0.5, 2.0),
            ("track_scale", 0.5, 2.0),
            ("steering_ratio", 0.5, 2.0),
        ):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and lo <= value <= hi):
                raise EmulatorValueError(name, value, f"a factor in {lo:g}..{hi:g}")
        for name in ("motor_flip", "encoder_flip"):
            value = getattr(self, name)
            if not (isinstance(value, int) and 0 <= value <= 3):
                raise EmulatorValueError(name, value, "a wheel bit mask 0..3")
        trim = self.steering_trim_deg
        if not (isinstance(trim, (int, float)) and math.isfinite(trim) and -20 <= trim <= 20):
            raise EmulatorValueError("steering_trim_deg", trim, "-20..20 degrees")

    @property
    def nominal(self) -> bool:
        """True when the robot is built exactly as configured."""
        return self == NOMINAL

    def describe(self) -> str:
        """The differences, e.g. "encoder_flip=1, cpr_scale=1.07" ("as configured" when none)."""
        parts = [f"{f.name}={getattr(self, f.name):g}" for f in fields(self) if getattr(self, f.name) != f.default]
        return ", ".join(parts) or "as configured"


NOMINAL = Physical()
MISCALIBRATED = Physical(cpr_scale=1.07, wheel_scale=0.95, track_scale=1.04, encoder_flip=1, steering_trim_deg=3.0)
"""A board whose configuration disagrees with its hardware: wheel 0's encoder is mirrored, the
encoders give 7 % more counts per revolution, the wheels are 5 % smaller and the track 4 % wider
than configured; on the PiCar the wheels point straight 3 degrees of servo past the configured
centre. (A linkage ratio, `steering_ratio`, is left out: with the PiCar servo's 0.5 degree
resolution no servo setting gives 15 degree steps to better than 1.3 % unless the ratio is 1.)"""

PRESETS: dict[str, Physical] = {"nominal": NOMINAL, "miscalibrated": MISCALIBRATED}
FIELD_NAMES: tuple[str, ...] = tuple(f.name for f in fields(Physical))


def physical_from(preset: str | None, overrides: dict[str, str]) -> Physical:
    """A preset (or NOMINAL) with fields replaced by `overrides` given as text (from a URL)."""
    if preset is not None and preset not in PRESETS:
        raise EmulatorValueError("physical", preset, f"one of {', '.join(PRESETS)}")
    base = PRESETS[preset or "nominal"]
    values: dict[str, float | int] = {f: getattr(base, f) for f in FIELD_NAMES}
    for key, text in overrides.items():
        kind = int if key.endswith("_flip") else float
        try:
            values[key] = kind(text)
        except ValueError:
            raise EmulatorValueError(key, text, "an integer" if kind is int else "a number") from None
    return Physical(**values)  # type: ignore[arg-type]
