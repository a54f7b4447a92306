"""The JY901 driver's thin I/O side.

    with Jy901.open("/dev/ttyUSB0") as imu:          # 115200 baud by default; or an emudev:// URL
        imu.configure(rate_hz=200, outputs=("acc", "gyro", "angle", "mag", "quat"))
        sample = imu.read()                           # ImuSample: SI units, the arrival time

Samples read together carry one arrival time; the driver spaces them back from it by the output
period (as the lidar driver does with its points). A period's packets make a sample only once the
next period's first packet is in, so the newest sample of a read is placed a period before the
read. A sample's `t` is thus when it was measured to within a period, and always after the sample
before it (a batch that arrives sooner than its periods would allow is spread over the time since
the last one), so samples stay in order and a gyro integrates over the right intervals.

Configuration writes are sent after the unlock command, as the newer firmware wants (older modules
ignore it); `configure(save=True)` stores them in the module's flash. A baud change switches this
port's speed too, right after the command has gone out.
"""

from __future__ import annotations

import dataclasses
from collections import deque
from collections.abc import Iterator, Sequence

from host_sdk.sensors import wit
from host_sdk.sensors.errors import SensorClosedError, SensorTimeoutError
from host_sdk.transport import Transport, open_transport
from protocol.sensors import DEVICES

DEFAULT_BAUD = DEVICES["jy901"].baud  # type: ignore[union-attr]
DEFAULT_RATE_HZ = DEVICES["jy901"].rate_hz  # type: ignore[union-attr]


class Jy901:
    def __init__(self, port: Transport) -> None:
        self.port = port
        self.parser = wit.WitParser()
        self._samples: deque[wit.ImuSample] = deque()
        self._registers: deque[wit.Registers] = deque()
        self.period_s = 1.0 / DEFAULT_RATE_HZ
        self._last_t: float | None = None
        """The output period the samples are spaced by (set by `configure(rate_hz=...)`)."""
        self.latest: dict[type, wit.Packet] = {}
        """The newest packet of each kind."""
        self._closed = False

    @classmethod
    def open(cls, url: str, baud: int = DEFAULT_BAUD) -> Jy901:
        return cls(open_transport(url, baud))

    @property
    def counters(self) -> wit.WitCounters:
        return self.parser.counters

    def _send(self, *commands: bytes) -> None:
        if self._closed:
            raise SensorClosedError(f"{self.port.url}: the IMU was closed")
        for c in commands:
            self.port.write(c)

    def configure(
        self,
        *,
        rate_hz: float | None = None,
        outputs: Sequence[str] | None = None,
        baud: int | None = None,
        six_axis: bool | None = None,
        save: bool = False,
    ) -> None:
        """Set what the module sends and how fast (ValueError names a value it does not support)."""
        commands = [wit.unlock()]
        if rate_hz is not None:
            commands.append(wit.set_rate(rate_hz))
            self.period_s = 1.0 / rate_hz
        if outputs is not None:
            commands.append(wit.set_outputs(*outputs))
        if six_axis is not None:
            commands.append(wit.set_axis6(six_axis))
        if baud is not None:
            commands.append(wit.set_baud(baud))
        if save:
            commands.append(wit.save())
        self._send(*commands)
        if baud is not None:
            self.port.set_baud(baud)

    def calibrate(self, mode: str) -> None:
        """accel (level and still), heading_zero, mag (turn it round, then calibrate("normal"))."""
        self._send(wit.unlock(), wit.calibrate(mode))

    def read_registers(self, addr: int, timeout_s: float = 1.0) -> tuple[int, int, int, int]:
        self._send(wit.read_registers(addr))
        deadline = self.port.clock() + timeout_s
        while not self._registers:
            self._wait_some(deadline, "register answer", timeout_s)
        return self._registers.popleft().values

    def read(self, timeout_s: float = 1.0) -> wit.ImuSample:
        """The next complete output period; SensorTimeoutError if none arrives in time."""
        deadline = self.port.clock() + timeout_s
        while not self._samples:
            self._wait_some(deadline, "IMU sample", timeout_s)
        return self._samples.popleft()

    def samples(self, timeout_s: float = 1.0) -> Iterator[wit.ImuSample]:
        while True:
            yield self.read(timeout_s)

    def poll(self, timeout_s: float = 0.0) -> list[wit.ImuSample]:
        self._pump(timeout_s)
        out = list(self._samples)
        self._samples.clear()
        return out

    def _wait_some(self, deadline: float, what: str, timeout_s: float) -> None:
        left = deadline - self.port.clock()
        if left <= 0:
            c = self.counters
            heard = f"{c.bytes_received} bytes, {c.packets} packets, {c.checksum_errors} bad checksums"
            raise SensorTimeoutError(self.port.url, what, timeout_s, heard)
        self._pump(min(left, 0.05))

    def _pump(self, timeout_s: float) -> None:
        if self._closed:
            raise SensorClosedError(f"{self.port.url}: the IMU was closed")
        data = self.port.read(timeout_s)
        if not data:
            return
        arrival = self.port.clock()
        self.parser.receive_data(data, arrival)
        events = self.parser.events()
        count = sum(isinstance(e, wit.ImuSample) for e in events)
        step = self.period_s
        if count and self._last_t is not None:
            step = min(step, max(arrival - self._last_t, 0.0) / (count + 1))
        for event in events:
            if isinstance(event, wit.ImuSample):
                # Spaced back from this read's arrival, not from the sample's own stamp: the first
                # sample of a read may carry the previous read's time (its period began there), and
                # spacing from that would stack the rest on one time.
                sample = dataclasses.replace(event, t=arrival - count * step)
                count -= 1
                self._last_t = sample.t
                self._samples.append(sample)
            elif isinstance(event, wit.Registers):
                self._registers.append(event)
            else:
                self.latest[type(event)] = event

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self.port.close()

    def __enter__(self) -> Jy901:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
