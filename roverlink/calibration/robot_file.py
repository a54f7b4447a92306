"""The calibration's measurements written into the user's robot file (docs/robot-file.md).

    roverlink calibrate /dev/ttyACM0 --robot my.toml --yes   # the measured values into [calibration]
    kin = host_sdk.RobotDescription.load("my.toml").kinematics()   # the next run uses them

The file is edited line by line (roverlink.robot_file_edit), so the rest of it (the user's
comments, order and layout) stays byte for byte; only what was measured is written (never the
wheelbase, which calibration does not measure): the measurements in `[calibration]`, and the
directions and servo pulses it found, which the firmware is built with, in their own sections.
The edited text is read back with protocol.robotfile before it replaces the file: a file the edit
would break is left as it was.
"""

from __future__ import annotations

from pathlib import Path

from host_sdk import RobotDescription
from roverlink import robot_file_edit as edit
from roverlink.calibration.procedure import CalibrationResult

SECTION = "calibration"


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


def build_facts(result: CalibrationResult, robot: RobotDescription) -> dict[str, dict[str, edit.Value]]:
    """What the calibration changed on the board that `[calibration]` has no key for, where the
    file says otherwise, as the file's keys by section: the motor and encoder directions and the
    servo's pulse span. They are compiled into the firmware (its defaults), not applied at connect."""
    after, own = result.config_after, robot.config()
    wheels = robot.drive.channels
    facts: dict[str, dict[str, edit.Value]] = {}
    if after.motor_invert != own.motor_invert:
        facts["drive"] = {"motor_invert": _flags(after.motor_invert, wheels)}
    if after.encoder_invert != own.encoder_invert and robot.wiring.encoders:
        facts["encoders"] = {"invert": _flags(after.encoder_invert, wheels)}
    if result.ackermann and (after.servo_min_us, after.servo_max_us) != (own.servo_min_us, own.servo_max_us):
        facts["steering"] = {"min_pulse_s": after.servo_min_us / 1e6, "max_pulse_s": after.servo_max_us / 1e6}
    return facts


def outside_section(result: CalibrationResult, robot: RobotDescription) -> list[str]:
    """`build_facts` as the lines to set in the file, `[section] key = value, ...`."""
    return [
        f"[{section}] " + ", ".join(f"{key} = {edit.toml_value(v)}" for key, v in keys.items())
        for section, keys in build_facts(result, robot).items()
    ]


def _flags(bits: int, wheels: int) -> tuple[bool, ...]:
    return tuple(bool(bits >> i & 1) for i in range(wheels))


def edited(text: str, values: dict[str, float | int]) -> str:
    """`text` with each of `values` set in `[calibration]` (roverlink.robot_file_edit.edited)."""
    return edit.edited(text, SECTION, dict(values))


def write_measured(
    path: str | Path, values: dict[str, float | int], facts: dict[str, dict[str, edit.Value]] | None = None
) -> Path:
    """Set `values` in the robot file's `[calibration]` (and `facts`, build_facts' keys, in their
    sections), checked to read back with them (RobotFileError or ValueError, file untouched, if not)."""
    return edit.plan(path, {SECTION: dict(values), **(facts or {})}).write()
