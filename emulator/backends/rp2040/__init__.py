"""The firmware on an RP2040 (Raspberry Pi Pico) in rp2040js, the fourth backend.

`harness.Harness` steps an SRAM image with the simavr harness's protocol: UART0 bytes both ways,
encoder positions in as quadrature edges, watched pins' levels out, on the chip's own clock.
"""

from emulator.backends.rp2040.harness import Harness, PinReading, Rp2040Error

__all__ = ["Harness", "PinReading", "Rp2040Error"]
