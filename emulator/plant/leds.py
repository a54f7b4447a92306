"""Turn-signal LEDs: what the firmware's light pins show, with a count of changes per LED."""

from __future__ import annotations

LED_NAMES = ("front_left", "front_right", "rear_left", "rear_right")
"""Bit i of the light mask drives LED_NAMES[i] (the firmware HAL's Lights bits)."""


class LedBank:
    __slots__ = ("mask", "toggles")

    def __init__(self) -> None:
        self.mask = 0
        self.toggles = [0, 0, 0, 0]

    def set(self, mask: int) -> None:
        changed = (self.mask ^ mask) & 0x0F
        for i in range(4):
            if changed >> i & 1:
                self.toggles[i] += 1
        self.mask = mask & 0x0F

    def states(self) -> dict[str, bool]:
        return {name: bool(self.mask >> i & 1) for i, name in enumerate(LED_NAMES)}
