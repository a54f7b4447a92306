"""Serial ports on this machine, with the ones that look like an Arduino marked (`roverlink ports`)."""

from __future__ import annotations

from dataclasses import dataclass

from serial.tools import list_ports

# USB vendor/product ids of boards and of the USB-serial chips Arduino clones use.
_GENUINE_VIDS = {0x2341: "Arduino", 0x2A03: "Arduino (arduino.org)", 0x1B4F: "SparkFun", 0x239A: "Adafruit"}
_BRIDGES = {
    (0x1A86, 0x7523): "CH340 USB-serial (common on Arduino clones)",
    (0x1A86, 0x55D4): "CH9102 USB-serial (common on Arduino clones)",
    (0x0403, 0x6001): "FTDI FT232R USB-serial (Arduino Duemilanove, Nano clones)",
    (0x10C4, 0xEA60): "CP210x USB-serial (Arduino clones)",
}


@dataclass(frozen=True, slots=True)
class PortInfo:
    device: str
    description: str
    vid: int | None
    pid: int | None
    serial_number: str | None
    likely_arduino: bool
    why: str


def classify(vid: int | None, pid: int | None) -> tuple[bool, str]:
    """(likely an Arduino, why) from USB ids."""
    if vid is None:
        return False, "not a USB device"
    if vid in _GENUINE_VIDS:
        return True, f"{_GENUINE_VIDS[vid]} board"
    bridge = _BRIDGES.get((vid, pid or 0))
    if bridge is not None:
        return True, bridge
    return False, "unknown USB device"


def list_serial_ports() -> list[PortInfo]:
    ports = []
    for p in sorted(list_ports.comports(), key=lambda p: str(p.device)):
        likely, why = classify(p.vid, p.pid)
        ports.append(PortInfo(str(p.device), str(p.description or ""), p.vid, p.pid, p.serial_number, likely, why))
    return ports
