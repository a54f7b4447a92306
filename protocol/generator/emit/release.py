"""Emit the release's version ([release] in the spec) into every place that states it.

Files whose whole content follows from the spec are generated whole. The ROS package's
package.xml is hand-written apart from its <version> element, which `stamp` rewrites and `check`
compares; pyproject.toml reads protocol/generated/version.py itself (a dynamic version).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

from protocol.generator.emit.common import GENERATOR, banner, json_with_banner
from protocol.generator.model import Spec

LICENSE = "MIT"
"""SPDX identifier of the project's licence (LICENSE at the root), named by every package."""

VERSION_PY = "protocol/generated/version.py"
VERSION_H = "arduino/RoverLink/src/core/version.h"
LIBRARY_PROPERTIES = "arduino/RoverLink/library.properties"
LIBRARY_JSON = "arduino/RoverLink/library.json"
"""The Arduino library's manifests: the Arduino IDE's and arduino-cli's, and PlatformIO's."""
ROS_PACKAGE_XML = "ros2/roverlink_ros/package.xml"

_LIBRARY_NAME = "RoverLink"
_LIBRARY_AUTHOR = "RoverLink maintainers"
_LIBRARY_HEADER = "RoverLink.h"
_ARCHITECTURES = {"avr": "atmelavr"}
"""The library's architectures: Arduino's name -> PlatformIO's platform."""
_KEYWORDS = ("robot", "serial", "protocol", "cobs", "crc", "motor", "encoder", "pid", "servo", "esc")
_LIBRARY_SENTENCE = "A checked, resynchronising serial link between a robot's host computer and its Arduino."
_LIBRARY_PARAGRAPH = (
    "COBS frames with CRC-16, a session with handshake, arming and failsafe watchdog, wheel-speed PID and "
    "feedback for differential-drive and Ackermann robots. Motor drivers (TB6612, L298N, BTS7960, RC ESC), "
    "steering servo and quadrature encoders for the Uno and the Mega 2560. No heap, no String, no "
    f"Serial.print. Licence: {LICENSE}."
)


def emit(spec: Spec) -> dict[str, str]:
    return {
        VERSION_PY: _version_py(spec),
        VERSION_H: _version_h(spec),
        LIBRARY_PROPERTIES: _library_properties(spec),
        LIBRARY_JSON: _library_json(spec),
    }


def _version_py(spec: Spec) -> str:
    major, minor, patch = spec.release
    return (
        banner(spec, "#")
        + '"""The release\'s version: every package\'s, and the firmware\'s IDENTITY.firmware_version."""\n\n'
        + "from typing import Final\n\n"
        + f'__version__: Final = "{spec.release_text}"\n'
        + f"VERSION: Final = ({major}, {minor}, {patch})\n"
        + f'LICENSE: Final = "{LICENSE}"\n'
    )


def _version_h(spec: Spec) -> str:
    major, minor, patch = spec.release
    return (
        banner(spec, "//")
        + "// The firmware version reported in IDENTITY.firmware_version.\n"
        + "#ifndef ROVERLINK_CORE_VERSION_H\n#define ROVERLINK_CORE_VERSION_H\n\n"
        + f"#define ROVERLINK_FIRMWARE_VERSION_MAJOR {major}\n"
        + f"#define ROVERLINK_FIRMWARE_VERSION_MINOR {minor}\n"
        + f"#define ROVERLINK_FIRMWARE_VERSION_PATCH {patch}\n"
        + f'#define ROVERLINK_FIRMWARE_VERSION "{spec.release_text}"\n\n'
        + "#endif  // ROVERLINK_CORE_VERSION_H\n"
    )


def _library_properties(spec: Spec) -> str:
    return (
        banner(spec, "#")
        + f"# SPDX-License-Identifier: {LICENSE}\n"
        + f"name={_LIBRARY_NAME}\n"
        + f"version={spec.release_text}\n"
        + f"author={_LIBRARY_AUTHOR}\n"
        + f"maintainer={_LIBRARY_AUTHOR}\n"
        + f"sentence={_LIBRARY_SENTENCE}\n"
        + f"paragraph={_LIBRARY_PARAGRAPH}\n"
        + "category=Communication\n"
        + f"architectures={','.join(_ARCHITECTURES)}\n"
        + f"includes={_LIBRARY_HEADER}\n"
    )


def _library_json(spec: Spec) -> str:
    """PlatformIO's manifest (JSON has no comments: the DO NOT EDIT line is the "_" key, which
    PlatformIO's manifest schema drops, as the test vectors carry theirs)."""
    manifest = {
        "name": _LIBRARY_NAME,
        "version": spec.release_text,
        "description": _LIBRARY_SENTENCE,  # PlatformIO's documentation: 255 characters at most
        "keywords": list(_KEYWORDS),
        "authors": [{"name": _LIBRARY_AUTHOR, "maintainer": True}],
        "license": LICENSE,
        "frameworks": ["arduino"],
        "platforms": list(_ARCHITECTURES.values()),
        "headers": [_LIBRARY_HEADER],
    }
    return json_with_banner(spec, manifest)


# -- stamped: one element of a hand-written file --------------------------------------------------

_PACKAGE_VERSION = re.compile(r"<version>[^<]*</version>")
_PACKAGE_LICENSE = re.compile(r"<license>[^<]*</license>")
_STAMP_NOTE = f"<!-- <version> and <license> are set by `{GENERATOR}` from the spec's [release]. -->"


def _stamp_package_xml(spec: Spec, text: str) -> str:
    for pattern, element in (
        (_PACKAGE_VERSION, f"<version>{spec.release_text}</version>"),
        (_PACKAGE_LICENSE, f"<license>{LICENSE}</license>"),
    ):
        if len(pattern.findall(text)) != 1:
            raise ValueError(f"{ROS_PACKAGE_XML}: expected exactly one {element.split('>')[0]}> element")
        text = pattern.sub(element, text)
    if _STAMP_NOTE not in text:
        text = text.replace("<package ", f"{_STAMP_NOTE}\n<package ", 1)
    return text


STAMPED: dict[str, Callable[[Spec, str], str]] = {ROS_PACKAGE_XML: _stamp_package_xml}
"""Hand-written files with generated parts: path -> (spec, current text) -> text it must be."""


def stamp(spec: Spec, root: Path) -> dict[str, str]:
    """The stamped files that exist under `root`, as they must read."""
    return {
        rel: fix(spec, (root / rel).read_text(encoding="utf-8"))
        for rel, fix in STAMPED.items()
        if (root / rel).exists()
    }
