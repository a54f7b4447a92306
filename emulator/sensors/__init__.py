"""Emulated sensors: RPLIDAR A1, YDLIDAR F4, WIT JY901 and the Pi Camera v2, in their wire formats.

    from emulator.sensors import attach
    rig = attach(emu, world="random:3", lidar="rplidar-a1", imu="jy901", camera=True)

See docs/sensors.md.
"""

from emulator.sensors.rig import BATCH_US, SensorRig, attach, camera_options

__all__ = ["BATCH_US", "SensorRig", "attach", "camera_options"]
