"""What every emulated serial sensor shares: its line to the host and its command input.

The device-to-host direction is a real `emulator.line.Line`: bytes are paced at the device's baud,
arrive after the USB adapter's latency, and can carry the line faults (`line.bitflip = 1e-4`...).
Host bytes are handed to the device when written (the commands are tiny; their own pacing is not
modelled), so a command takes effect at the virtual time it was written.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from emulator.line import Line
from emulator.rng import Streams
from emulator.sensors.lidar import LidarModel, LidarSamples, PoseAt
from emulator.world.scene import Scene
from protocol.sensors import LidarSpec

LATENCY_US = 1000
"""USB-serial adapter latency of the sensor ports (as the board's default)."""


class SerialSensor:
    """Base of the emulated lidars and IMU: `host_write`, `host_read`, `update`."""

    kind = "device"

    def __init__(self, name: str, baud: int, streams: Streams, log: Callable[[int, str, str], None]) -> None:
        self.name = name
        self.tx = Line(f"{name}:d2h", baud, LATENCY_US, rng=streams.get(f"line:{name}"), log=log)
        self.rng = np.random.Generator(np.random.PCG64(streams.get(f"sensor:{name}").getrandbits(64)))
        self.bytes_from_host = 0
        self.unknown_commands = 0

    def host_write(self, data: bytes, now_us: int) -> None:
        """Bytes the host wrote, handled at `now_us`."""
        self.bytes_from_host += len(data)
        self.on_bytes(data, now_us)

    def host_read(self, now_us: int) -> bytes:
        """Every byte that has reached the host by `now_us`."""
        return self.tx.receive(now_us)

    def send(self, data: bytes, at_us: int) -> None:
        self.tx.send(data, at_us)

    # -- what each device implements ----------------------------------------------------------------
    def on_bytes(self, data: bytes, now_us: int) -> None:
        raise NotImplementedError

    def update(self, scene: Scene, until_us: int, pose_at: PoseAt) -> None:
        """Produce everything due before `until_us` (called every few ms of virtual time)."""
        raise NotImplementedError


class LidarDevice(SerialSensor):
    """A lidar on its port: the model, the scanning state, and the last batch (ground truth)."""

    kind = "lidar"

    def __init__(
        self, spec: LidarSpec, model: LidarModel, streams: Streams, log: Callable[[int, str, str], None]
    ) -> None:
        super().__init__("lidar", spec.baud, streams, log)
        self.spec = spec
        self.model = model
        model.rng = self.rng
        self.scanning = False
        self._rx = bytearray()
        self.last_samples: LidarSamples | None = None
        """The last batch of samples, with each one's noise-free range."""
        self.on_rear: Callable[[int], None] | None = None
        """Ground truth for a host's scan stamps: called with the time (us) of each sample at which
        the rotor has passed the device's 180 deg, the rear, where a LaserScan's ray 0 (-pi) lies."""
        self._angle: float | None = None

    def update(self, scene: Scene, until_us: int, pose_at: PoseAt) -> None:
        samples = self.model.sample(scene, until_us, pose_at)
        if samples is not None:
            self.last_samples = samples
            if self.on_rear is not None:
                # The rotor angle only grows (mod 360): a pass of 180 deg is where it wraps, seen
                # from 180 deg.
                behind = np.mod(samples.angle_deg - 180.0, 360.0)
                before = np.concatenate([[behind[0] if self._angle is None else self._angle], behind[:-1]])
                for t_us in samples.time_us[behind < before].tolist():
                    self.on_rear(int(t_us))
                self._angle = float(behind[-1])
            self.emit(samples)

    def emit(self, samples: LidarSamples) -> None:
        """Put a batch of samples on the wire."""
        raise NotImplementedError
