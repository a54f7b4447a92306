"""The robot's lidar and IMU on the graph: `scan` (sensor_msgs/LaserScan) and `imu` (sensor_msgs/Imu).

Each device runs on a thread of its own with its host_sdk.sensors driver (docs/sensors.md): open,
start, read, publish; a device that fails or goes quiet is closed and opened again a second later,
and says so in its own diagnostics status (any exception: an unexpected one is logged as such,
once, and the thread carries on). Stamps are the driver's times, mapped to ROS time like
odometry's: an IMU sample's arrival; a scan's ray 0's measurement time, with `time_increment` the
signed time from ray to ray (host_sdk.sensors.laserscan: one revolution per message, cut at the
rear; stamps the scanner had to rewrite make the lidar's status WARN: stamp_rewrites). Against
`emu://...&lidar=MODEL&imu=jy901` the emulated devices are used unless a `lidar_url`/`imu_url`
parameter names another port.
"""

from __future__ import annotations

import contextlib
import dataclasses
import threading
import time
from typing import Any, Protocol

from rclpy.node import Node
from rclpy.qos import QoSProfile, qos_profile_sensor_data
from sensor_msgs.msg import Imu, LaserScan

from host_sdk import RoverLinkError
from host_sdk.sensors import ImuSample, Jy901, LaserScanner, Lidar
from host_sdk.sensors.imu import DEFAULT_BAUD
from roverlink.ros2 import convert
from roverlink.ros2.diagnostics import ERROR, OK, WARN, Report
from roverlink.ros2.params import BridgeParams
from roverlink.ros2.stamp_rewrites import StampRewrites

_BEST_EFFORT = qos_profile_sensor_data.reliability
RETRY_S = 1.0
QUIET_S = 2.0
"""No data for this long: the device is reported as silent (ERROR)."""


class SensorPublisher:
    """A device on its own thread: subclasses open it, read one item and publish it."""

    kind = ""
    baud: int | None = None
    """The line speed the device is opened at (None: its datasheet's); set before __init__."""

    def __init__(self, node: Node, url: str, frame: str) -> None:
        self.node = node
        self.url = url
        self.frame = frame
        self.count = 0
        self.opened = 0
        self.error = ""
        self._logged = ""
        """The failure last logged (cleared by a published message)."""
        self.last_s: float | None = None
        self._times: list[float] = []
        self._device: Any = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name=f"roverlink-{self.kind}", daemon=True)
        self._thread.start()

    def _open(self) -> Any:
        raise NotImplementedError

    def _read_and_publish(self, device: Any) -> None:
        raise NotImplementedError

    def counters(self) -> dict[str, int]:
        device = self._device
        return {} if device is None else {k: int(v) for k, v in dataclasses.asdict(device.counters).items()}

    def stamp_ns(self, device: Any, t: float) -> int:
        return convert.stamp_ns(t, device.port.clock(), self.node.get_clock().now().nanoseconds)

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                self._device = self._open()
                self.opened += 1
                self.error = ""
                while not self._stop.is_set():
                    self._read_and_publish(self._device)
                    now = time.monotonic()
                    self.count += 1
                    self.last_s = now
                    self._logged = ""
                    self._times = [t for t in self._times[-50:] if t > now - 5.0] + [now]
            except Exception as exc:  # any failure: report it, reopen, never die
                if not self._stop.is_set():
                    self._failed(exc)
            finally:
                self._close()
            self._stop.wait(RETRY_S)

    def _failed(self, exc: Exception) -> None:
        """Log a failure once (until it changes) and show it in the diagnostics status. A device's
        own errors are expected (unplugged, silent); anything else is a bug, named as such."""
        expected = isinstance(exc, RoverLinkError | OSError)
        text = str(exc) if expected else f"unexpected {type(exc).__name__}: {exc}"
        if text != self._logged:  # once per failure, not once per retry
            self._logged = text
            log = self.node.get_logger()
            (log.warning if expected else log.error)(f"{self.kind} on {self.url}: {text}; retrying")
        self.error = text

    def _close(self) -> None:
        device, self._device = self._device, None
        if device is not None:
            with contextlib.suppress(Exception):  # what failed may fail to close too: never kill the thread
                device.close()

    def close(self) -> None:
        self._stop.set()
        self._thread.join(5.0)
        self._close()

    def report(self, node_name: str) -> Report:
        now = time.monotonic()
        times = [t for t in self._times if t > now - 5.0]
        rate = (len(times) - 1) / (times[-1] - times[0]) if len(times) > 2 and times[-1] > times[0] else 0.0
        values = [("url", self.url), ("baud", str(self.baud or "the datasheet's")), ("frame", self.frame)]
        values.append((f"{self.kind} messages", str(self.count)))
        values += [("rate (Hz)", f"{rate:.1f}"), ("opened", str(self.opened))]
        values += [(k.replace("_", " "), str(v)) for k, v in self.counters().items()]
        if self.error:
            level, message = ERROR, self.error
        elif self.last_s is None or now - self.last_s > QUIET_S:
            level, message = (ERROR if self.opened else WARN), "no data"
        else:
            level, message = OK, f"{rate:.1f} Hz"
        return Report(level, f"{node_name}: {self.kind}", message, self.url, tuple(values))


class LidarPublisher(SensorPublisher):
    kind = "lidar"

    def __init__(self, node: Node, url: str, model: str, frame: str, bins: int, *, baud: int | None = None) -> None:
        self.model, self.bins, self.baud = model, bins, baud
        self.scanner = LaserScanner(bins, clockwise=True)
        self.rewrites = StampRewrites()
        self.pub = node.create_publisher(LaserScan, "scan", QoSProfile(depth=5, reliability=_BEST_EFFORT))
        super().__init__(node, url, frame)

    def _open(self) -> Lidar:
        lidar = Lidar.open(self.url, self.model, self.baud)
        self.scanner = LaserScanner(self.bins, clockwise=lidar.spec.clockwise)  # afresh on each open
        lidar.start()
        return lidar

    def _read_and_publish(self, lidar: Any) -> None:
        # One message per revolution, cut at the rear (host_sdk.sensors.laserscan): stamp and
        # time_increment are the rays' measurement times.
        for scan in self.scanner.push(lidar.read_scan(timeout_s=QUIET_S)):
            msg = LaserScan()
            convert.fill_laser_scan(msg, ns=self.stamp_ns(lidar, scan.time_s), frame=self.frame, scan=scan)
            self.pub.publish(msg)
        self.rewrites.update(self.scanner, time.monotonic())

    def report(self, node_name: str) -> Report:
        return self.rewrites.apply(super().report(node_name), time.monotonic())


class ImuListener(Protocol):
    """Takes each IMU sample too (the EKF), with the port's clock read right after it arrived."""

    def on_imu(self, sample: ImuSample, port_now: float) -> None: ...


class ImuPublisher(SensorPublisher):
    kind = "imu"

    def __init__(
        self,
        node: Node,
        url: str,
        params: BridgeParams,
        listener: ImuListener | None = None,
        *,
        baud: int | None = None,
    ) -> None:
        self.baud = baud or DEFAULT_BAUD
        """The robot file's [sensors.imu] baud or the imu_baud parameter (roverlink.ros2.params.sensor_baud)."""
        self.pub = node.create_publisher(Imu, "imu", QoSProfile(depth=10, reliability=_BEST_EFFORT))
        self.covariance = convert.ImuCovariance(
            params.imu_orientation_covariance_diagonal,
            params.imu_angular_velocity_covariance_diagonal,
            params.imu_linear_acceleration_covariance_diagonal,
        )
        self.listener = listener
        super().__init__(node, url, params.imu_frame)

    def _open(self) -> Jy901:
        return Jy901.open(self.url, self.baud or DEFAULT_BAUD)

    def _read_and_publish(self, imu: Any) -> None:
        sample = imu.read(timeout_s=QUIET_S)
        if self.listener is not None:
            self.listener.on_imu(sample, imu.port.clock())
        msg = Imu()
        ns = self.stamp_ns(imu, sample.t)
        convert.fill_imu(msg, ns=ns, frame=self.frame, sample=sample, covariance=self.covariance)
        self.pub.publish(msg)
