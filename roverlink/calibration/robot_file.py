"""The calibration's measurements written into the user's robot file (docs/robot-file.md).

    roverlink calibrate /dev/ttyACM0 --robot my.toml --yes   # the measured values into [calibration]
    kin = host_sdk.RobotDescription.load("my.toml").kinematics()   # the next run uses them

Only the `[calibration]` section is edited, line by line, so the rest of the file (the user's
comments, order and layout) stays byte for byte; only what was measured is written (never the
wheelbase, which calibration does not measure). The edited text is read back with
protocol.robotfile before it replaces the file: a file the edit would break is left as it was.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

from host_sdk import RobotDescription
from protocol.robotfile import RobotFileError, parse
from roverlink.calibration.procedure import CalibrationResult

SECTION = "calibration"
_HEADER = re.compile(r"^\s*\[\s*([A-Za-z0-9_.\"' -]+?)\s*\]\s*(#.*)?$")
_TABLE_ARRAY = re.compile(r"^\s*\[\[")


def measured(result: CalibrationResult, robot: RobotDescription) -> dict[str, float | int]:
    """The `[calibration]` keys the calibration measured, in the file's units."""
    after = result.config_after
    values: dict[str, float | int] = {
        "wheel_diameter_m": round(after.wheel_diameter_um / 1e6, 6),
        "counts_per_rev": after.encoder_cpr,
    }
    if not result.ackermann:
        values["track_m"] = round(result.track_after_m, 6)
    elif result.wheelbase_m and robot.steering is not None:
        # The steering was measured (it needs the wheelbase): the centre as a trim on the file's.
        values["steering_trim_deg"] = round(after.steering_center_cdeg / 100 - robot.steering.center_deg, 2)
    return values


def outside_section(result: CalibrationResult, robot: RobotDescription) -> list[str]:
    """What the calibration changed on the board that `[calibration]` has no key for and the file
    says otherwise: where to change the file by hand (the board's EEPROM has it already)."""
    after, own = result.config_after, robot.config()
    wheels = robot.drive.channels
    notes = []
    if after.motor_invert != own.motor_invert:
        notes.append(f"[drive] motor_invert = {_flags(after.motor_invert, wheels)}")
    if after.encoder_invert != own.encoder_invert and robot.wiring.encoders:
        notes.append(f"[encoders] invert = {_flags(after.encoder_invert, wheels)}")
    if result.ackermann and (after.servo_min_us, after.servo_max_us) != (own.servo_min_us, own.servo_max_us):
        notes.append(
            f"[steering] min_pulse_s = {after.servo_min_us / 1e6:g}, max_pulse_s = {after.servo_max_us / 1e6:g}"
        )
    return notes


def _flags(bits: int, wheels: int) -> str:
    return "[" + ", ".join("true" if bits >> i & 1 else "false" for i in range(wheels)) + "]"


def _toml(value: float | int) -> str:
    if isinstance(value, int):
        return str(value)
    if not math.isfinite(value):
        raise ValueError(f"measured value {value!r} is not a number")
    return repr(float(value))


def _section_span(lines: list[str]) -> tuple[int, int] | None:
    """(first line after the header, end) of the `[calibration]` table; None if there is none."""
    start = None
    for i, line in enumerate(lines):
        header = _HEADER.match(line)
        if header is None and not _TABLE_ARRAY.match(line):
            continue
        if start is not None:
            return start, i
        if header is not None and header.group(1).strip("\"'") == SECTION:
            start = i + 1
    return None if start is None else (start, len(lines))


def edited(text: str, values: dict[str, float | int]) -> str:
    """`text` with each of `values` set in `[calibration]`: an existing `key = ...` line is
    replaced (its trailing comment kept), a commented-out template line `# key = ...` becomes the
    key, anything else is added at the end of the section (the section at the end of the file if
    there is none). Every other line is kept as it is."""
    newline = "\r\n" if "\r\n" in text else "\n"
    lines = text.splitlines(keepends=True)
    span = _section_span(lines)
    if span is None:
        if lines and not lines[-1].endswith(("\n", "\r")):
            lines[-1] += newline
        lines += [newline, f"[{SECTION}]{newline}"]
        span = (len(lines), len(lines))
    start, end = span
    for key, value in values.items():
        at = _line_of(lines[start:end], key)
        if at is not None:
            at += start
            match = _assignment(key).match(lines[at])
            assert match is not None  # _line_of found it with the same pattern
            indent, _hash, comment, ending = match.groups()
            ending = ending or ("" if at == len(lines) - 1 else newline)
            lines[at] = f"{indent}{key} = {_toml(value)}{comment or ''}{ending}"
            continue
        at = end
        while at > start and not lines[at - 1].strip():
            at -= 1  # after the section's last line, before the blank lines that end it
        if at > 0 and not lines[at - 1].endswith(("\n", "\r")):
            lines[at - 1] += newline
        lines.insert(at, f"{key} = {_toml(value)}{newline}")
        end += 1
    return "".join(lines)


def _assignment(key: str) -> re.Pattern[str]:
    """`key = value  # comment`, or the same commented out: (indent, '#', comment, line end)."""
    return re.compile(rf"^(\s*)(#\s*)?{re.escape(key)}\s*=\s*[^#\r\n]*?(\s*#[^\r\n]*)?(\r?\n)?$")


def _line_of(lines: list[str], key: str) -> int | None:
    """The line that sets `key`, else the commented-out template line for it."""
    pattern = _assignment(key)
    matches = [(i, m) for i, line in enumerate(lines) if (m := pattern.match(line)) is not None]
    for i, m in matches:
        if m.group(2) is None:
            return i
    return matches[0][0] if matches else None


def write_measured(path: str | Path, values: dict[str, float | int]) -> Path:
    """Set `values` in the robot file's `[calibration]` and check the result reads back with
    them (RobotFileError, file untouched, if not)."""
    where = Path(path)
    text = edited(where.read_text(encoding="utf-8"), values)
    robot, problems = parse(text, str(where))
    if robot is None:
        raise RobotFileError(problems)
    got = {key: getattr(robot.calibration, key) for key in values}
    if got != values:  # e.g. the values also set elsewhere (a dotted key): the file wins, say so
        raise ValueError(f"{where}: [calibration] could not be set to {values} (reads back {got}): edit it by hand")
    temp = where.with_name(f".{where.name}.calibrating")
    with open(temp, "w", encoding="utf-8", newline="") as out:
        out.write(text)
    os.replace(temp, where)  # whole or not at all: a robot file is never left half written
    return where
