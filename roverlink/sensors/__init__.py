"""The command line's choice of host-side sensors (lidar, IMU, camera) beside the board.

`choose_sensors(args, robot)` takes the devices the command line names (`add_sensor_args`) and
those an `emu://` URL attached; `open_sensors(choice)` opens them as a `Sensors` hub that reads
them (threads on real ports, `poll()` on an emulator's virtual clock), calls listeners with every
scan, IMU sample and frame, and keeps the status the monitor shows. `host_sdk.recording.SensorSource`
records them; `roverlink.calibration.ImuObserver` measures turns with the IMU.
"""

from roverlink.sensors.options import (
    SensorChoice,
    add_sensor_args,
    camera_source,
    choose_sensors,
    open_imu,
    open_lidar,
    open_sensors,
)

__all__ = [
    "SensorChoice",
    "add_sensor_args",
    "camera_source",
    "choose_sensors",
    "open_imu",
    "open_lidar",
    "open_sensors",
]
