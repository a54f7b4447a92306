"""Guided calibration: motor and encoder directions, counts per revolution, wheel diameter,
track width or steering, each measured by an observer (a person, or the emulator's truth; turns by
the IMU when there is one).

See roverlink.calibration.procedure for the steps and `roverlink calibrate` for the command; what
it measures goes into a robot file's [calibration] (roverlink.calibration.robot_file, read by
host_sdk.RobotDescription) or the JSON file host_sdk.calibration reads.
"""

from roverlink.calibration.imu import ImuObserver, ImuTurn, measure_turn
from roverlink.calibration.observer import EmulatorObserver, Observer, PersonObserver, observer_for
from roverlink.calibration.procedure import Calibration, CalibrationResult, Check, restore, verify
from roverlink.calibration.store import save_file

__all__ = [
    "Calibration",
    "CalibrationResult",
    "Check",
    "EmulatorObserver",
    "ImuObserver",
    "ImuTurn",
    "Observer",
    "PersonObserver",
    "measure_turn",
    "observer_for",
    "restore",
    "save_file",
    "verify",
]
