"""The plant's parameters, and how a robot file gives them: its `[emulator.*]` sections (the
physics the firmware cannot know: protocol/robotfile/schema.py has every key and its range), its
gearbox (`[geometry] gear_ratio`), its ESC and servo pulses (`[esc]`, `[steering]`) and its board.

The reader checks the sections as data; the models' types stay here. A section a file leaves out is
taken from a stand-in robot's file (the nearest reference robot: emulator.robot_file).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, cast

from emulator.plant.esc import EscParams
from emulator.plant.motor import MotorParams
from emulator.plant.servo import ServoParams
from emulator.plant.vehicle import BodyParams
from protocol.robotfile import RobotFile
from protocol.robotfile.model import Values
from protocol.robotfile.schema import key


@dataclass(frozen=True, slots=True)
class BoardTiming:
    bootloader_ms: int
    """Time from an external (DTR) reset to the sketch's setup(); power-on skips the bootloader."""
    power_on_ms: int = 70
    """Start-up delay after power-on or brown-out (oscillator start-up and setup())."""
    eeprom_bytes: int = 4096
    eeprom_write_ms: float = 3.4
    """Time to program one changed EEPROM byte; the main loop is stalled meanwhile."""
    rx_buffer_bytes: int = 63
    """Usable bytes of the Arduino core's 64-byte receive ring buffer."""
    micros_resolution_us: int = 4
    """micros() steps of 4 us on a 16 MHz AVR (timer0 prescaler 64)."""


@dataclass(frozen=True, slots=True)
class PlantParams:
    motor: MotorParams
    body: BodyParams
    timing: BoardTiming
    esc: EscParams | None = None
    servo: ServoParams | None = None
    encoder_phase: float = 0.0
    """Fraction of a count between an encoder edge and the power-up position (0: on an edge)."""


_MEGA = BoardTiming(bootloader_ms=1500, eeprom_bytes=4096)
_UNO = BoardTiming(bootloader_ms=1000, eeprom_bytes=1024)
# The Pico: no serial bootloader (its boot ROM, boot block and clock set-up: taken as 10 ms, not
# measured on a board), no EEPROM (its
# firmware keeps no configuration), the UART's 32-byte FIFO, a 1 MHz timer.
_PICO = BoardTiming(bootloader_ms=10, power_on_ms=10, eeprom_bytes=0, rx_buffer_bytes=32, micros_resolution_us=1)
TIMINGS: dict[str, BoardTiming] = {"mega2560": _MEGA, "uno": _UNO, "pico": _PICO, "native": _MEGA}
"""Board timing by a robot file's `board` (the native core: the Mega's, the larger EEPROM)."""


_MARGIN = key("emulator.servo", "travel_margin_deg")
"""Its default applies when neither file has an [emulator.servo]."""


def _us(seconds: float) -> int:
    return round(seconds * 1e6)


def _section(robot: RobotFile, stand_in: RobotFile, part: str) -> tuple[RobotFile, Values]:
    """The file that gives [emulator.<part>] (the robot's, else the stand-in's) and its values."""
    for source in (robot, stand_in):
        values = getattr(source.emulator, part)
        if values is not None:
            return source, values
    return stand_in, ()


def _motor(robot: RobotFile, stand_in: RobotFile) -> MotorParams:
    source, values = _section(robot, stand_in, "motor")
    if not values:
        raise ValueError(f"{stand_in.path}: no [emulator.motor] to stand in for {robot.path}'s")
    # the motor comes with its gearbox: the file that gives the motor gives the ratio
    return MotorParams(**dict(values), gear_ratio=source.geometry.gear_ratio)


def _body(robot: RobotFile, stand_in: RobotFile) -> BodyParams:
    _, values = _section(robot, stand_in, "body")
    if not values:
        raise ValueError(f"{stand_in.path}: no [emulator.body] to stand in for {robot.path}'s")
    return BodyParams(**dict(values))


def _esc(robot: RobotFile, stand_in: RobotFile) -> EscParams | None:
    e = robot.esc
    if e is None:
        return None
    values: dict[str, Any] = dict(_section(robot, stand_in, "esc")[1])  # the reader's int keys are ints
    pulses = {"min_us": _us(e.min_pulse_s), "max_us": _us(e.max_pulse_s), "nominal_neutral_us": _us(e.neutral_pulse_s)}
    return dataclasses.replace(EscParams(), **values, **pulses)


def _servo(robot: RobotFile, stand_in: RobotFile) -> ServoParams | None:
    s = robot.steering
    if s is None:
        return None
    values = dict(_section(robot, stand_in, "servo")[1])
    margin = values.pop("travel_margin_deg", cast(float, _MARGIN.default))
    return dataclasses.replace(
        ServoParams(),
        **values,
        min_us=_us(s.min_pulse_s),
        max_us=_us(s.max_pulse_s),
        travel_min_deg=max(0.0, s.min_deg - margin),
        travel_max_deg=min(180.0, s.max_deg + margin),
        straight_deg=s.center_deg,
    )


def plant_from_file(robot: RobotFile, stand_in: RobotFile) -> PlantParams:
    """The plant of the robot the file describes: its [emulator.*] sections (each one it leaves
    out: `stand_in`'s), its gearbox, ESC and servo pulses, and its board's timing."""
    return PlantParams(
        motor=_motor(robot, stand_in),
        body=_body(robot, stand_in),
        timing=TIMINGS[robot.board],
        esc=_esc(robot, stand_in),
        servo=_servo(robot, stand_in),
    )
