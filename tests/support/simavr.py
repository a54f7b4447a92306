"""The example ELFs for simavr tests, built with the tools' firmware builder (cached by content).

The emulator runs a firmware, it does not compile one: tests build it here and pass `elf=`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from emulator.backends.simavr import SimavrRobot
from emulator.profiles import get_profile
from roverlink import firmware


def example_elf(profile: str) -> Path:
    """The ELF of the firmware example of `profile` (e.g. "picar" -> AckermannPiCar.elf)."""
    example = get_profile(profile).robot.example
    return firmware.build_example(example, out_dir=firmware.BUILD_ROOT / "simavr" / example).elf


def simavr_robot(profile: str, **options: Any) -> SimavrRobot:
    """SimavrRobot(profile, elf=<the example's ELF>, **options)."""
    return SimavrRobot(profile, elf=example_elf(profile), **options)
