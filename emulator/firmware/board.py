"""What the firmware model needs from its board: the Python twin of arduino/.../hal/board.h.

The firmware owns every decision (session, PID, limits, pulse widths, light patterns); a Board
only moves pins, counts edges, keeps time and stores bytes. The emulator's board drives the plant.
The values it is handed (MotorMode, the Lights bits) are the hardware contract both sides share,
protocol/spec/hardware.toml (generated: protocol.generated.hardware).
"""

from __future__ import annotations

from typing import Protocol

from protocol.generated.hardware import MotorMode


class Board(Protocol):
    eeprom_size: int
    """Bytes of EEPROM (the boot counter lives in the last four)."""

    def micros(self) -> int:
        """Microseconds since the sketch started (u32, wraps)."""
        ...

    def read_encoders(self) -> list[int]:
        """Cumulative raw counts per wheel channel (before encoder_invert), read atomically."""
        ...

    def zero_encoders(self) -> None: ...

    def drive(self, wheel: int, effort_permille: int, mode: MotorMode) -> None:
        """DC motor of `wheel`: signed effort (already corrected for motor_invert) and mode."""
        ...

    def esc_pulse(self, pulse_us: int) -> None: ...

    def steering_pulse(self, pulse_us: int) -> None: ...

    def lights(self, mask: int) -> None:
        """Lights bits."""
        ...

    def eeprom_read(self, address: int, length: int) -> bytes: ...

    def eeprom_write(self, address: int, data: bytes) -> bool:
        """Programs the bytes (only those that differ, like EEPROM.update); stalls the loop."""
        ...

    def entropy(self) -> int:
        """32 bits of physical noise (ADC, timer jitter) for the boot_id."""
        ...

    def serial_write(self, data: bytes) -> None: ...
