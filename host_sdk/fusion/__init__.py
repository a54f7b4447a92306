"""Sensor fusion: wheel odometry + IMU gyro (+ optional magnetometer) in an EKF (`PoseEkf`).

numpy only; see docs/autonomy.md.
"""

from host_sdk.fusion.ekf import EkfParams, FusedPose, OdometryIncrements, PoseEkf, compass_heading

__all__ = ["EkfParams", "FusedPose", "OdometryIncrements", "PoseEkf", "compass_heading"]
