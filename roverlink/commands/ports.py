"""`roverlink ports`: serial ports, with the likely Arduinos marked."""

from __future__ import annotations

import argparse

from host_sdk.ports import list_serial_ports


def cmd_ports(_args: argparse.Namespace) -> int:
    """List serial ports; likely Arduinos (by USB vendor/product id) are marked with *."""
    ports = list_serial_ports()
    if not ports:
        print("no serial ports found (is the board plugged in? on Linux, are you in the dialout group?)")
        return 0
    for p in ports:
        ids = f"{p.vid:04X}:{p.pid or 0:04X}" if p.vid is not None else "-"
        mark = "*" if p.likely_arduino else " "
        print(f"{mark} {p.device:<22} {ids:<10} {p.description}  ({p.why})")
    if any(p.likely_arduino for p in ports):
        print("\n* likely an Arduino: try `roverlink info PORT`")
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    sub.add_parser("ports", help=cmd_ports.__doc__, description=cmd_ports.__doc__).set_defaults(func=cmd_ports)
