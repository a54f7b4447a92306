"""The firmware on an RP2040 (Raspberry Pi Pico) in rp2040js, the fourth backend.

harness.py  the rp2040js process (tools/rp2040/harness.mjs): an image stepped with the simavr
            harness's protocol (UART0 bytes both ways, encoder positions in as quadrature
            edges, watched pins' duty, levels and pulses out), on the chip's own clock
robot.py    Rp2040Robot: a Pico robot's flash image in the harness inside the plant loop;
            pico_profile(): a reference robot moved to the Pico pinout, or a Pico robot file
"""

from emulator.backends.rp2040.harness import Harness, PinReading, Rp2040Error
from emulator.backends.rp2040.robot import Rp2040Robot, decode, pico_profile, pico_robot, watched_pins

__all__ = [
    "Harness",
    "PinReading",
    "Rp2040Error",
    "Rp2040Robot",
    "decode",
    "pico_profile",
    "pico_robot",
    "watched_pins",
]
