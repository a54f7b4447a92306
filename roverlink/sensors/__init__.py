"""The host-side sensors the bring-up tools read beside the board (lidar, IMU, camera).

`choose_sensors(args, robot)` takes the devices the command line names (`add_sensor_args`) and
those an `emu://` URL attached; `open_sensors(choice)` opens them as a `Sensors` hub that reads
them (threads on real ports, `poll()` on an emulator's virtual clock), calls listeners with every
scan, IMU sample and frame, and keeps the status the monitor shows. `roverlink.recording.SensorSource`
records them; `roverlink.calibration.ImuObserver` measures turns with the IMU.
"""

from roverlink.sensors.hub import CameraStatus, ImuStatus, LidarStatus, Sensors, SensorStatus
from roverlink.sensors.options import SensorChoice, add_sensor_args, camera_source, choose_sensors, open_sensors

__all__ = [
    "CameraStatus",
    "ImuStatus",
    "LidarStatus",
    "SensorChoice",
    "SensorStatus",
    "Sensors",
    "add_sensor_args",
    "camera_source",
    "choose_sensors",
    "open_sensors",
]
