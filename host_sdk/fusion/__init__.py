"""Sensor fusion: wheel odometry + IMU gyro (+ optional magnetometer) in an EKF (`PoseEkf`), and the
pose a robot program's loop reads (`PoseSource`: the EKF's with an IMU, else wheel odometry).

numpy only; see docs/autonomy.md.
"""

from host_sdk.fusion.ekf import FusedPose, OdometryIncrements, PoseEkf, compass_heading
from host_sdk.fusion.ekf_params import DIFF_DRIVE_PARAMS, EkfParams, params_for
from host_sdk.fusion.source import PoseSource

__all__ = [
    "DIFF_DRIVE_PARAMS",
    "EkfParams",
    "FusedPose",
    "OdometryIncrements",
    "PoseEkf",
    "PoseSource",
    "compass_heading",
    "params_for",
]
