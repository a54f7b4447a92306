"""Ways for host code to reach the emulator: an in-memory serial port on the virtual clock, and a
pseudo-terminal or a TCP socket served in real time."""

from emulator.transport.memory import MemorySerial

__all__ = ["MemorySerial"]
