"""The host's half of a calibration: what the board has no setting for (the track width).

    roverlink calibrate /dev/ttyACM0 -o calibration.json
    kin = load_kinematics("calibration.json")
    robot = Robot.connect("/dev/ttyACM0", kinematics=kin)

The file is JSON: the robot's name, the kinematics with every calibrated value, and the board
configuration changes (already saved in the board's EEPROM; kept here as the record).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from host_sdk import Ackermann, DiffDrive
from roverlink.calibration.procedure import CalibrationResult

FORMAT = "roverlink-calibration/1"


def save_file(path: str | Path, result: CalibrationResult, robot_name: str) -> Path:
    kin = result.kinematics()
    data: dict[str, Any] = {
        "format": FORMAT,
        "robot": robot_name,
        "kinematics": {"type": "ackermann" if isinstance(kin, Ackermann) else "diff", **_fields(kin)},
        "board_changes": {name: [_plain(a), _plain(b)] for name, a, b in result.changes()},
        "findings": result.findings,
    }
    out = Path(path)
    out.write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")
    return out


def load_kinematics(path: str | Path) -> DiffDrive | Ackermann:
    """The calibrated kinematics in a file written by `roverlink calibrate -o`."""
    data = json.loads(Path(path).read_text(encoding="utf-8"))
    if data.get("format") != FORMAT:
        raise ValueError(f"{path}: not a {FORMAT} file (format {data.get('format')!r})")
    kin = dict(data["kinematics"])
    kind = kin.pop("type")
    return Ackermann(**kin) if kind == "ackermann" else DiffDrive(**kin)


def _fields(kin: DiffDrive | Ackermann) -> dict[str, float]:
    return {name: getattr(kin, name) for name in kin.__dataclass_fields__}


def _plain(value: object) -> object:
    return getattr(value, "name", value)
