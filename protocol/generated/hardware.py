# DO NOT EDIT: generated from protocol/spec/hardware.toml by `python -m protocol generate`.
"""The hardware contract: what the firmware core hands to its board (arduino/RoverLink/src/hal/board.h),
as the emulator's board model and plant and the native tests read it. Not on the wire."""

import enum


class MotorMode(enum.IntEnum):
    """How a DC motor driver holds a wheel."""

    DRIVE = 0
    """PWM duty |effort| / 1000 in the effort's direction."""
    COAST = 1
    """Outputs off: no current flows, the wheel turns freely."""
    BRAKE = 2
    """Terminals shorted, back-EMF brakes (TB6612/L298N: both inputs high; BTS7960: both PWM 0, enables high)."""


class Lights(enum.IntFlag):
    """Turn-signal / status lights, one bit each (the patterns: docs/firmware.md, Lights)."""

    FRONT_LEFT = 0x1
    """Front left LED."""
    FRONT_RIGHT = 0x2
    """Front right LED."""
    REAR_LEFT = 0x4
    """Rear left LED."""
    REAR_RIGHT = 0x8
    """Rear right LED."""


__all__ = ["MotorMode", "Lights"]
