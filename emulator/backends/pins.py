"""What an MCU's output pins tell the hardware around it, whichever MCU it is: the decoded state
(duty and mode per motor channel, pulse widths, LEDs) the plant loop applies, and the motor
drivers' truth tables (docs/control.md section 5) that turn pin levels into it."""

from __future__ import annotations

from dataclasses import dataclass

from protocol.generated.hardware import MotorMode


@dataclass(frozen=True)
class PinState:
    """What the MCU's pins tell the hardware around it, decoded from one register snapshot."""

    duty: tuple[float, ...]
    """Signed duty per DC motor channel, -1..1 (PWM duty in the driven direction)."""
    mode: tuple[MotorMode, ...]
    esc_us: int
    """0: no pulses."""
    servo_us: int
    leds: int
    """Lights bits."""

    def effort_permille(self, wheel: int) -> int:
        return round(self.duty[wheel] * 1000) if wheel < len(self.duty) else 0


RELEASED = PinState((0.0, 0.0), (MotorMode.COAST, MotorMode.COAST), 0, 0, 0)
"""Every output released (in reset, in the bootloader)."""


def hbridge(in1: bool, in2: bool, standby: bool | None, duty: float) -> tuple[float, MotorMode]:
    """TB6612 (`standby`: its STBY level, None when tied high) or L298N channel: IN1/IN2 both low
    (or STBY low) coast, both high brake, else `duty` (0..1 of the PWM input) in IN1's direction."""
    if standby is False or (not in1 and not in2):
        return 0.0, MotorMode.COAST
    if in1 and in2:
        return 0.0, MotorMode.BRAKE
    return (duty if in1 else -duty), MotorMode.DRIVE


def bts7960(r_en: bool, l_en: bool, forward: float, reverse: float) -> tuple[float, MotorMode]:
    """BTS7960 pair: enables low coast; enables high with both PWM 0 brake (both low sides on)."""
    if not (r_en and l_en):
        return 0.0, MotorMode.COAST
    if forward == 0.0 and reverse == 0.0:
        return 0.0, MotorMode.BRAKE
    return forward - reverse, MotorMode.DRIVE
