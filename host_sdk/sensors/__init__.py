"""Drivers for the reference robots' host-side sensors (docs/sensors.md).

Each protocol is a sans-I/O parser (`receive_data(bytes, t)`, then its events), with a thin class
that owns the port (a host_sdk.transport Transport, opened by `open_transport` as the board's is):

- `Lidar`: RPLIDAR A1 (`rplidar.RPLidarParser`) and YDLIDAR F4 (`ydlidar.YDLidarParser`), whole
  revolutions as `LidarScan` with a time on every point; `LaserScanner` (laserscan.py) re-cuts them
  at the rear into REP-117 `LaserScanData`, the fields of a ROS LaserScan;
- `Jy901`: the WIT standard protocol (`wit.WitParser`), samples in SI units, configuration;
- `CameraSource`: frames from picamera2, V4L2, GStreamer (where OpenCV has it), MJPEG over HTTP
  and byte streams (`mjpeg.MjpegParser`), or a replay, with capture times and dropped-frame counts
  (the `camera` package, a module per route).

The same classes open real devices (`/dev/ttyUSB0`, `/dev/video0`) and an emulator's devices
(the `emudev://` URLs an `emu://` robot lists in `transport.endpoints`). numpy is the only
dependency here; OpenCV (and picamera2) are imported by the camera source when it opens.

`Sensors` (hub.py) reads a lidar, an IMU and a camera together beside the robot's loop and keeps
their status; `DeviceReader` and `FrameGrabber` (reader.py) are its pieces: a thread per device on a
real port, `poll()` on an emulator's virtual clock.
"""

from host_sdk.sensors.camera import CameraFrame, CameraSource, gstreamer_pipeline
from host_sdk.sensors.errors import SensorClosedError, SensorOpenError, SensorTimeoutError
from host_sdk.sensors.hub import CameraStatus, ImuStatus, LidarStatus, Sensors, SensorStatus
from host_sdk.sensors.imu import Jy901
from host_sdk.sensors.laserscan import LaserScanData, LaserScanner
from host_sdk.sensors.lidar import Lidar
from host_sdk.sensors.reader import DeviceReader, FrameGrabber
from host_sdk.sensors.scan import LidarCounters, LidarScan, RegularScan
from host_sdk.sensors.wit import ImuSample

__all__ = [
    "CameraFrame",
    "CameraSource",
    "CameraStatus",
    "DeviceReader",
    "FrameGrabber",
    "ImuSample",
    "ImuStatus",
    "Jy901",
    "LaserScanData",
    "LaserScanner",
    "Lidar",
    "LidarCounters",
    "LidarScan",
    "LidarStatus",
    "RegularScan",
    "SensorClosedError",
    "SensorOpenError",
    "SensorStatus",
    "SensorTimeoutError",
    "Sensors",
    "gstreamer_pipeline",
]
