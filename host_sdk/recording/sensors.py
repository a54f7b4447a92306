"""The host-side sensors as a recording source: scans, images and IMU samples, and where each sits.

    sensors = open_sensors(choose_sensors(args, robot))      # roverlink.sensors
    with Recorder.attach(robot, mcap_path="run.mcap", sources=[SensorSource(sensors, mounts)]):
        ...

| topic | schema | from |
|---|---|---|
| `/scan` | `foxglove.LaserScan` | each revolution on `scan_bins` even angles (the nearest return per bin) |
| `/camera/image/compressed` | `foxglove.CompressedImage` | each frame: the stream's JPEG, or the image encoded |
| `/imu` | JSON `roverlink.Imu` | each output period of the IMU |
| `/tf` | `foxglove.FrameTransforms` | `base_link -> laser`, `-> imu`, `-> camera` (once a second) |

Each message carries the driver's own time for it: a scan its first point's, a frame the time it
came off the driver, an IMU sample its arrival. The source starts the sensors (the lidar spins
up) when the recording starts and reads the virtual-clock ones in `poll()`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

from host_sdk.extras import require
from host_sdk.recording.schemas import (
    FRAME_BASE,
    FRAME_CAMERA,
    FRAME_IMU,
    FRAME_LASER,
    IMU_SCHEMA,
    SENSOR_FRAMES,
    TOPIC_IMAGE,
    TOPIC_IMU,
    TOPIC_SCAN,
    TOPIC_TF,
    imu_message,
)
from host_sdk.recording.sink import Publisher
from host_sdk.sensors import CameraFrame, ImuSample, LidarScan
from host_sdk.sensors.hub import Sensors
from protocol.sensors import Mount

SCAN_BINS = 360
JPEG_QUALITY = 85


def laser_scan_fields(scan: LidarScan, bins: int = SCAN_BINS) -> dict[str, Any]:
    """The LaserScan fields of a revolution: `bins` angles from -pi, evenly spaced, the nearest
    return in each (NaN: none), and the strongest quality as the intensity."""
    regular = scan.regular(bins)
    return {
        "start_angle": regular.angle_min,
        "end_angle": regular.angle_min + (bins - 1) * regular.angle_increment,
        "ranges": regular.ranges_m.tolist(),
        "intensities": regular.intensities.tolist(),
    }


def frame_jpeg(frame: CameraFrame) -> bytes:
    """The frame's JPEG: as the stream carried it, else encoded (OpenCV, quality 85)."""
    if frame.jpeg is not None:
        return frame.jpeg
    cv2 = require("cv2", "vision", "recording the camera")  # loaded already: the camera source opened it
    ok, data = cv2.imencode(".jpg", frame.image, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
    if not ok:
        raise ValueError(f"frame {frame.seq}: OpenCV could not encode it as JPEG")
    return bytes(data)


class SensorSource:
    """Publishes what a `Sensors` hub's drivers deliver (see the module docstring)."""

    name = "sensors"

    def __init__(
        self,
        sensors: Sensors,
        mounts: Mapping[str, Mount] | None = None,
        *,
        scan_bins: int = SCAN_BINS,
        tf_period_s: float = 1.0,
    ) -> None:
        if scan_bins < 1:
            raise ValueError(f"scan_bins = {scan_bins!r} is not allowed: a whole number >= 1")
        self.sensors = sensors
        self.mounts = dict(mounts or {})
        self.scan_bins = scan_bins
        self.tf_period_s = tf_period_s
        self._out: Publisher | None = None
        self._unsubscribe: list[Callable[[], None]] = []
        self._last_tf: float | None = None

    def start(self, out: Publisher) -> None:
        self._out = out
        s = self.sensors
        self._unsubscribe = [s.on_scan(self._on_scan), s.on_imu(self._on_imu), s.on_frame(self._on_frame)]
        s.start()

    def stop(self) -> None:
        for unsubscribe in self._unsubscribe:
            unsubscribe()
        self._unsubscribe = []
        self._out = None

    def poll(self, now_s: float) -> None:
        self.sensors.poll()
        if self._out is not None and (self._last_tf is None or now_s - self._last_tf >= self.tf_period_s):
            self._last_tf = now_s
            for kind in self.sensors.kinds():
                m = self.mounts.get(kind) or Mount(kind, kind)
                self._out.transform(
                    TOPIC_TF,
                    now_s,
                    parent=FRAME_BASE,
                    child=SENSOR_FRAMES[kind],
                    x=m.x_m,
                    y=m.y_m,
                    z=m.z_m,
                    theta=math.radians(m.yaw_deg),
                )

    def _on_scan(self, scan: LidarScan) -> None:
        out = self._out
        if out is not None and len(scan):
            out.laser_scan(TOPIC_SCAN, scan.time_s, frame_id=FRAME_LASER, **laser_scan_fields(scan, self.scan_bins))

    def _on_imu(self, sample: ImuSample) -> None:
        out = self._out
        if out is not None:
            out.json(TOPIC_IMU, IMU_SCHEMA, imu_message(sample, FRAME_IMU), sample.t)

    def _on_frame(self, frame: CameraFrame) -> None:
        out = self._out
        if out is not None:
            out.compressed_image(TOPIC_IMAGE, frame.time_s, frame_id=FRAME_CAMERA, fmt="jpeg", data=frame_jpeg(frame))
