"""The host's half of a calibration: what the board has no setting for (the track width), written
to the calibration file of host_sdk.calibration with the calibration's record.

    roverlink calibrate /dev/ttyACM0 -o calibration.json
    kin = load_kinematics("calibration.json")
    robot = Robot.connect("/dev/ttyACM0", kinematics=kin)
"""

from __future__ import annotations

from pathlib import Path

from host_sdk.calibration import write_calibration
from roverlink.calibration.procedure import CalibrationResult


def save_file(path: str | Path, result: CalibrationResult, robot_name: str) -> Path:
    """The calibrated kinematics, the board's changes and the findings, as JSON."""
    return write_calibration(
        path,
        robot_name,
        result.kinematics(),
        board_changes={name: [_plain(a), _plain(b)] for name, a, b in result.changes()},
        findings=result.findings,
    )


def _plain(value: object) -> object:
    return getattr(value, "name", value)
