"""The turn signals as the host chooses them (SET_LIGHTS) and as the board reports them (LIGHTS_STATE).

Three modes (docs/protocol.md, LightsMode): AUTO (the firmware's own patterns from the motion
state), OFF (dark) and MANUAL (each lamp steady, blinking slowly at 1.5 Hz or fast at 3 Hz). A lamp
set is given as Lights bits (`Lights.FRONT_LEFT | Lights.REAR_LEFT`), a whole number 0..15, lamp
names (`"left"`, `["front_left", "rear_right"]`) or a comma-separated text of them (`"left,front"`).

The text form, shared by `describe()` and `parse()` (the ROS 2 bridge's `~/lights` topic), is
`auto`, `off` or `manual steady=LAMPS slow=LAMPS fast=LAMPS` (each key optional, `-` for none).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from host_sdk import checks
from host_sdk.errors import ArgumentTypeError, CommandRangeError
from protocol.generated.enums import LightsMode
from protocol.generated.hardware import Lights
from protocol.generated.messages import LightsState, SetLights

LAMPS: dict[str, int] = {
    "front_left": int(Lights.FRONT_LEFT),
    "front_right": int(Lights.FRONT_RIGHT),
    "rear_left": int(Lights.REAR_LEFT),
    "rear_right": int(Lights.REAR_RIGHT),
}
"""Each lamp by name, as its Lights bit."""

GROUPS: dict[str, int] = {
    "left": LAMPS["front_left"] | LAMPS["rear_left"],
    "right": LAMPS["front_right"] | LAMPS["rear_right"],
    "front": LAMPS["front_left"] | LAMPS["front_right"],
    "rear": LAMPS["rear_left"] | LAMPS["rear_right"],
    "all": 0xF,
}
"""Names for several lamps at once."""

PATTERNS = ("steady", "slow", "fast")
"""MANUAL's patterns, as SET_LIGHTS names its masks."""

_ALLOWED = "Lights bits, a whole number 0..15, or lamp names (" + ", ".join([*LAMPS, *GROUPS]) + ")"


def lamp_mask(name: str, value: object) -> int:
    """A lamp set as its Lights bits (0..15); `name` is the argument, for the error."""
    if isinstance(value, Lights):
        return int(value)
    if isinstance(value, str):
        words = [w.strip() for w in value.split(",") if w.strip()]
        if value.strip() in ("", "-"):
            return 0
        if value.strip().isdigit():  # the text form of the bits, as a ROS 2 string carries them
            return lamp_mask(name, int(value))
        return lamp_mask(name, words)
    if isinstance(value, Mapping):
        raise ArgumentTypeError(name, value, _ALLOWED)
    if isinstance(value, Iterable):
        mask = 0
        for word in value:
            if not isinstance(word, str):
                raise ArgumentTypeError(name, value, _ALLOWED)
            bits = LAMPS.get(word, GROUPS.get(word))
            if bits is None:
                raise CommandRangeError(name, word, _ALLOWED)
            mask |= bits
        return mask
    return checks.integer(name, value, 0, 15, what="Lights bits")


def _names(mask: int) -> str:
    if mask == 0:
        return "-"
    if mask == GROUPS["all"]:
        return "all"
    for group, bits in GROUPS.items():
        if mask == bits:
            return group
    return ",".join(n for n, bit in LAMPS.items() if mask & bit)


def request(
    mode: LightsMode | str | None = None,
    *,
    steady: object = None,
    slow: object = None,
    fast: object = None,
) -> SetLights:
    """The SET_LIGHTS for these arguments, every one checked. A lamp set given without a mode means
    MANUAL; AUTO and OFF take none."""
    masks = {"steady": steady, "slow": slow, "fast": fast}
    given = {k: lamp_mask(k, v) for k, v in masks.items() if v is not None}
    if mode is None:
        if not given:
            raise CommandRangeError("mode", None, "auto, off or manual (or lamps for steady, slow or fast)")
        chosen = LightsMode.MANUAL
    elif isinstance(mode, LightsMode):
        chosen = mode
    else:
        chosen = LightsMode[checks.choice("mode", mode.lower() if isinstance(mode, str) else mode, _MODES).upper()]
    if chosen is not LightsMode.MANUAL and given:
        first = next(iter(given))
        raise CommandRangeError(first, masks[first], f"no lamps in mode {chosen.name.lower()} (only manual takes them)")
    return SetLights(mode=chosen, steady=given.get("steady", 0), slow=given.get("slow", 0), fast=given.get("fast", 0))


_MODES = tuple(m.name.lower() for m in LightsMode if m.name)


def parse(text: str) -> SetLights:
    """The SET_LIGHTS a text asks for: `auto`, `off`, or `manual` with `steady=`, `slow=`, `fast=`
    (lamp names separated by commas). CommandRangeError names what is wrong."""
    checks.text("lights", text, allowed="auto, off, or manual steady=LAMPS slow=LAMPS fast=LAMPS")
    words = text.split()
    if not words:
        raise CommandRangeError("lights", text, "auto, off, or manual steady=LAMPS slow=LAMPS fast=LAMPS")
    masks: dict[str, str] = {}
    for word in words[1:]:
        key, eq, value = word.partition("=")
        if key == "lit" and eq:
            continue  # what describe() reports lit: a reading, not a request
        if not eq or key not in PATTERNS:
            raise CommandRangeError("lights", word, "steady=LAMPS, slow=LAMPS or fast=LAMPS")
        if key in masks:
            raise CommandRangeError("lights", word, f"{key}= once (the lamps of a pattern in one word, by commas)")
        masks[key] = value
    return request(words[0], **masks)


@dataclass(frozen=True)
class LightsStatus:
    """The turn signals as the board reported them (GET_LIGHTS)."""

    mode: LightsMode
    """Who drives them: AUTO (the firmware's patterns), OFF or MANUAL."""
    steady: Lights
    """MANUAL: lamps lit steadily."""
    slow: Lights
    """MANUAL: lamps blinking at 1.5 Hz."""
    fast: Lights
    """MANUAL: lamps blinking at 3 Hz."""
    lit: Lights
    """The lamps lit at the board's last control tick."""

    @classmethod
    def of(cls, reply: LightsState) -> LightsStatus:
        return cls(reply.mode, Lights(reply.steady), Lights(reply.slow), Lights(reply.fast), Lights(reply.lit))

    def describe(self) -> str:
        """The text form (`parse` reads it back, `lit=` aside): e.g. `manual steady=- slow=left fast=- lit=left`."""
        head = self.mode.name.lower() if self.mode.name else str(int(self.mode))
        if self.mode is LightsMode.MANUAL:
            head += "".join(f" {p}={_names(int(getattr(self, p)))}" for p in PATTERNS)
        return f"{head} lit={_names(int(self.lit))}"
