"""The lidar drivers' thin I/O side: a port, a parser, and waiting with a deadline.

    with Lidar.open("/dev/ttyUSB0", "rplidar-a1") as lidar:     # or "ydlidar-f4"; or an emudev:// URL
        print(lidar.health())
        lidar.start()
        scan = lidar.read_scan()                             # one whole revolution (LidarScan)

Everything protocol-specific is in the sans-I/O parsers (rplidar.py, ydlidar.py); this class writes
their requests, feeds them what the port delivers, stamped with the port's clock on arrival, and
hands back their events. Waiting is bounded by deadlines on that clock; no fixed sleeps.
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any

from host_sdk.sensors import rplidar, ydlidar
from host_sdk.sensors.errors import SensorClosedError, SensorTimeoutError
from host_sdk.sensors.scan import DeviceHealth, DeviceInfo, LidarCounters, LidarScan
from host_sdk.transport import Transport, open_transport
from protocol.sensors import LidarSpec, device

MODELS = ("rplidar-a1", "ydlidar-f4")


class Lidar:
    def __init__(self, port: Transport, model: str = "rplidar-a1") -> None:
        spec = device(model, "lidar")
        assert isinstance(spec, LidarSpec)
        self.spec = spec
        self.port = port
        self.model = model
        self.parser: rplidar.RPLidarParser | ydlidar.YDLidarParser
        if spec.protocol == "rplidar":
            self.parser = rplidar.RPLidarParser(spec)
        else:
            self.parser = ydlidar.YDLidarParser(spec)
        self._queue: deque[Any] = deque()
        self._closed = False
        self._quiet_until = -math.inf

    @classmethod
    def open(cls, url: str, model: str = "rplidar-a1", baud: int | None = None) -> Lidar:
        """Open the lidar on `url` (a serial device, a pyserial URL, or an emudev:// endpoint). A
        lidar left scanning by an earlier program is stopped first: what it still sends is skipped."""
        spec = device(model, "lidar")
        assert isinstance(spec, LidarSpec)
        lidar = cls(open_transport(url, baud or spec.baud), model)
        lidar.stop()
        return lidar

    @property
    def counters(self) -> LidarCounters:
        return self.parser.counters

    @property
    def is_rplidar(self) -> bool:
        return self.spec.protocol == "rplidar"

    # -- requests -------------------------------------------------------------------------------------
    def _request(self, code: int) -> None:
        self._check_open()
        # The RPLIDAR protocol asks for 1 ms after STOP (2 ms after RESET) before the next request:
        # read (and skip) what is still arriving until then.
        while (left := self._quiet_until - self.port.clock()) > 0:
            self._pump(left)
        self.port.write(rplidar.request(code) if self.is_rplidar else ydlidar.command(code))
        if code in (rplidar.STOP, rplidar.RESET) and self.is_rplidar:
            self._quiet_until = self.port.clock() + (0.002 if code == rplidar.STOP else 0.003)

    def _ask(self, code: int, kind: type, what: str, timeout_s: float) -> Any:
        if self.parser.scanning:
            self.stop()
        self._request(code)
        return self._wait(kind, what, timeout_s)

    def info(self, timeout_s: float = 1.0) -> DeviceInfo:
        code = rplidar.GET_INFO if self.is_rplidar else ydlidar.GET_INFO
        info: DeviceInfo = self._ask(code, DeviceInfo, "device info", timeout_s)
        return info

    def health(self, timeout_s: float = 1.0) -> DeviceHealth:
        code = rplidar.GET_HEALTH if self.is_rplidar else ydlidar.GET_HEALTH
        health: DeviceHealth = self._ask(code, DeviceHealth, "health answer", timeout_s)
        return health

    def sample_rate(self, timeout_s: float = 1.0) -> rplidar.SampleRate:
        """RPLIDAR only: the sample durations (the parser then times nodes with them)."""
        rate: rplidar.SampleRate = self._ask(rplidar.GET_SAMPLERATE, rplidar.SampleRate, "sample rate", timeout_s)
        return rate

    def start(self) -> None:
        """Spin up (the A1 adapter's DTR low runs its motor) and start scanning."""
        if self.is_rplidar:
            self.port.set_dtr(False)
        self._queue.clear()
        self._request(rplidar.SCAN if self.is_rplidar else ydlidar.START_SCAN)
        self.parser.expect_scan()

    def stop(self) -> None:
        self._request(rplidar.STOP if self.is_rplidar else ydlidar.STOP_SCAN)
        self.parser.reset()
        self._queue.clear()

    # -- data -----------------------------------------------------------------------------------------
    def read_scan(self, timeout_s: float = 2.0) -> LidarScan:
        """The next whole revolution; SensorTimeoutError if none completes in time."""
        scan: LidarScan = self._wait(LidarScan, "whole scan", timeout_s)
        return scan

    def poll(self, timeout_s: float = 0.0) -> list[LidarScan]:
        """The revolutions completed so far (reading for at most `timeout_s`)."""
        self._pump(timeout_s)
        scans = [e for e in self._queue if isinstance(e, LidarScan)]
        self._queue = deque(e for e in self._queue if not isinstance(e, LidarScan))
        return scans

    def _pump(self, timeout_s: float) -> None:
        data = self.port.read(timeout_s)
        if data:
            self.parser.receive_data(data, self.port.clock())
            self._queue.extend(self.parser.events())

    def _wait(self, kind: type, what: str, timeout_s: float) -> Any:
        self._check_open()
        deadline = self.port.clock() + timeout_s
        while True:
            for event in self._queue:
                if isinstance(event, kind):
                    self._queue.remove(event)
                    return event
            left = deadline - self.port.clock()
            if left <= 0:
                c = self.counters
                heard = f"{c.bytes_received} bytes, {c.points} points, {c.bytes_discarded} discarded"
                raise SensorTimeoutError(self.port.url, what, timeout_s, heard)
            self._pump(min(left, 0.05))

    def _check_open(self) -> None:
        if self._closed:
            raise SensorClosedError(f"{self.port.url}: the lidar was closed")

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self.port.close()

    def __enter__(self) -> Lidar:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
