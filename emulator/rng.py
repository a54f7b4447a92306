"""Seeded random streams: one independent, named stream per consumer.

Each consumer (a line direction, boot ids, the bootloader's garbage...) draws from its own stream,
derived from the seed and the stream's name. Changing one fault rate therefore does not shift the
random numbers another part sees, and the same seed always gives the same numbers (Python seeds a
`random.Random` from a str through SHA-512, independent of PYTHONHASHSEED).
"""

from __future__ import annotations

import random


class Streams:
    def __init__(self, seed: int) -> None:
        self.seed = seed
        self._streams: dict[str, random.Random] = {}

    def get(self, name: str) -> random.Random:
        stream = self._streams.get(name)
        if stream is None:
            stream = self._streams[name] = random.Random(f"roverlink-emulator:{self.seed}:{name}")
        return stream
