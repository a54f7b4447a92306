"""Emit the hardware contract: the C++ header the HAL includes and the Python module the emulator uses."""

from __future__ import annotations

from protocol.generator.emit.common import GENERATOR
from protocol.generator.emit.cpp import enum_decl
from protocol.generator.emit.python import doc, enum_classes
from protocol.generator.hardware import Hardware

HEADER = "arduino/RoverLink/src/generated/roverlink_hardware.h"
MODULE = "protocol/generated/hardware.py"


def emit(hardware: Hardware) -> dict[str, str]:
    return {HEADER: _header(hardware), MODULE: _module(hardware)}


def _banner(hardware: Hardware, comment: str) -> str:
    return f"{comment} DO NOT EDIT: generated from {hardware.path} by `{GENERATOR}`.\n"


def _header(hardware: Hardware) -> str:
    out = [_banner(hardware, "//")]
    out.append("// The hardware contract: what the portable core hands to a Board (hal/board.h). Not on the wire.\n")
    out.append("#ifndef ROVERLINK_GENERATED_HARDWARE_H\n#define ROVERLINK_GENERATED_HARDWARE_H\n\n")
    out.append("#include <stdint.h>\n\nnamespace roverlink {\n\n")
    out.extend(enum_decl(e) for e in hardware.enums)
    out.append("}  // namespace roverlink\n\n#endif  // ROVERLINK_GENERATED_HARDWARE_H\n")
    return "".join(out)


def _module(hardware: Hardware) -> str:
    text = (
        "The hardware contract: what the firmware core hands to its board (arduino/RoverLink/src/hal/board.h),\n"
        "as the emulator's board model and plant and the native tests read it. Not on the wire."
    )
    return _banner(hardware, "#") + doc(text) + enum_classes(hardware.enums)
