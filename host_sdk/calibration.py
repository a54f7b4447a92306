"""The host's calibration file: what the board has no setting for.

The board's configuration holds the wheel diameter, the encoder counts and the steering; it has no
field for a differential-drive robot's track width, which only the host's odometry and kinematics
use. `roverlink calibrate` writes it here, with the rest of the kinematics:

    roverlink calibrate /dev/ttyACM0 -o calibration.json          # writes the file
    roverlink teleop /dev/ttyACM0 --kinematics calibration.json   # every command with a URL takes it
    robot = Robot.connect("/dev/ttyACM0", kinematics=host_sdk.calibration.load_kinematics("calibration.json"))

The file is JSON: the format, the robot's firmware name, the kinematics with every value, and the
board configuration changes and findings of the calibration (already in the board's EEPROM; kept
as the record).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from host_sdk.errors import RoverLinkError
from host_sdk.kinematics import Ackermann, DiffDrive

FORMAT = "roverlink-calibration/1"
_KINDS: dict[str, type[DiffDrive] | type[Ackermann]] = {"diff": DiffDrive, "ackermann": Ackermann}


class KinematicsFileError(RoverLinkError, ValueError):
    """A calibration file that cannot be used; names the file and what is wrong."""


@dataclass(frozen=True, slots=True)
class CalibrationFile:
    path: Path
    robot: str
    """The firmware's robot name it was calibrated on (IDENTITY.robot_name)."""
    kinematics: DiffDrive | Ackermann


def read_calibration(path: str | Path) -> CalibrationFile:
    """The file written by `roverlink calibrate -o` (OSError if it cannot be read)."""
    where = Path(path)
    try:
        data = json.loads(where.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise KinematicsFileError(f"{where}: not JSON ({exc})") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        found = data.get("format") if isinstance(data, dict) else None
        raise KinematicsFileError(f"{where}: not a {FORMAT} file (format {found!r}): roverlink calibrate -o writes one")
    kin = data.get("kinematics")
    kind = kin.get("type") if isinstance(kin, dict) else None
    cls = _KINDS.get(str(kind))
    if cls is None:
        raise KinematicsFileError(f"{where}: kinematics.type = {kind!r} is not allowed: one of {', '.join(_KINDS)}")
    assert isinstance(kin, dict)
    values = {k: v for k, v in kin.items() if k != "type"}
    names = {f.name for f in fields(cls)}
    if set(values) - names:
        extra = sorted(set(values) - names)[0]
        raise KinematicsFileError(f"{where}: kinematics.{extra} is not a field of {cls.__name__}: {', '.join(names)}")
    try:
        kinematics = cls(**values)
    except (TypeError, ValueError) as exc:
        raise KinematicsFileError(f"{where}: {exc}") from None
    return CalibrationFile(where, str(data.get("robot", "")), kinematics)


def load_kinematics(path: str | Path) -> DiffDrive | Ackermann:
    """The calibrated kinematics in a file written by `roverlink calibrate -o`, for
    `Robot.connect(url, kinematics=...)`."""
    return read_calibration(path).kinematics


def write_calibration(path: str | Path, robot: str, kinematics: DiffDrive | Ackermann, **record: Any) -> Path:
    """Write the file (`record`: further JSON values kept with it, e.g. the board's changes)."""
    kind = next(name for name, cls in _KINDS.items() if isinstance(kinematics, cls))
    values = {f.name: getattr(kinematics, f.name) for f in fields(kinematics)}
    data: dict[str, Any] = {"format": FORMAT, "robot": robot, "kinematics": {"type": kind, **values}, **record}
    out = Path(path)
    out.write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")
    return out
