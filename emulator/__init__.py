"""RoverLink firmware emulator: a Python reference model of the firmware and a vehicle plant.

    from emulator import Emulator
    emu = Emulator("diffdrive-tb6612", seed=1, faults="bitflip=1e-4")

See docs/emulator.md.
"""

from emulator.device import Emulator, McuPhase
from emulator.errors import EmulatorError, EmulatorValueError, FaultSpecError, UnknownProfileError
from emulator.faults import FaultSpec, parse_faults
from emulator.profiles import PROFILE_NAMES, EmulatorProfile, get_profile
from emulator.truth import Truth

__all__ = [
    "PROFILE_NAMES",
    "Emulator",
    "EmulatorError",
    "EmulatorProfile",
    "EmulatorValueError",
    "FaultSpec",
    "FaultSpecError",
    "McuPhase",
    "Truth",
    "UnknownProfileError",
    "get_profile",
    "parse_faults",
]
