"""The RPLIDAR A1 as its serial port shows it (Slamtec's interface protocol for A1/A2).

Requests: `A5 cmd` or, with bit 7 of cmd set, `A5 cmd size payload... checksum` (XOR of all bytes
before it). Answers start with a 7-byte descriptor `A5 5A len(30 bits LE) | mode << 30, type`.

| request | answer |
|---|---|
| STOP `A5 25` | none; scanning stops |
| RESET `A5 40` | none on the protocol; the core reboots and prints its text banner |
| SCAN `A5 20`, FORCE_SCAN `A5 21` | `A5 5A 05 00 00 40 81`, then 5-byte nodes until STOP |
| GET_INFO `A5 50` | `A5 5A 14 00 00 00 04`: model, firmware minor, major, hardware, 16-byte serial |
| GET_HEALTH `A5 52` | `A5 5A 03 00 00 00 06`: status (0 good), error code u16 |
| GET_SAMPLERATE `A5 59` | `A5 5A 04 00 00 00 15`: Tstandard u16, Texpress u16 (us) |

A node: `quality << 2 | !S << 1 | S`, `angle_q6 << 1 | 1` (u16 LE), `distance_q2` (u16 LE); S marks
the first node of a revolution, angle_q6 is degrees * 64, distance_q2 millimetres * 4, 0 = no
return. EXPRESS_SCAN and the other requests with a payload are accepted and not answered (this model
has the standard mode only). The A1's motor is switched by the adapter's DTR line, which a pty
cannot carry: the emulated motor spins whenever the device is powered.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from emulator.rng import Streams
from emulator.sensors.lidar import LidarModel, LidarSamples
from emulator.sensors.serial import LidarDevice
from protocol.sensors import LidarSpec, Mount

SYNC = 0xA5
STOP, RESET, SCAN, FORCE_SCAN = 0x25, 0x40, 0x20, 0x21
GET_INFO, GET_HEALTH, GET_SAMPLERATE = 0x50, 0x52, 0x59
HAS_PAYLOAD = 0x80


def descriptor(length: int, mode: int, type_: int) -> bytes:
    """The 7-byte response descriptor (mode 0: single answer, 1: multiple)."""
    return bytes([SYNC, 0x5A]) + (length | mode << 30).to_bytes(4, "little") + bytes([type_])


def encode_nodes(samples: LidarSamples) -> list[bytes]:
    """One 5-byte node per sample."""
    s = samples.start.astype(np.int64)
    q = np.clip(samples.quality, 0, 63)
    b0 = (q << 2) | ((1 - s) << 1) | s
    angle = np.rint(samples.angle_deg * 64).astype(np.int64) % (360 * 64)
    dist = np.clip(np.rint(samples.range_m * 4000), 0, 0xFFFF).astype(np.int64)
    raw = np.column_stack([b0, ((angle & 0x7F) << 1) | 1, angle >> 7, dist & 0xFF, dist >> 8]).astype(np.uint8)
    return [row.tobytes() for row in raw]


class RPLidarA1(LidarDevice):
    def __init__(self, spec: LidarSpec, mount: Mount, streams: Streams, log: Callable[[int, str, str], None]) -> None:
        super().__init__(spec, LidarModel(spec, mount, None), streams, log)
        self.serial_number = bytes(self.rng.integers(0, 256, 16, dtype=np.uint8))

    def on_bytes(self, data: bytes, now_us: int) -> None:
        rx = self._rx
        rx += data
        while rx:
            if rx[0] != SYNC:
                del rx[0]
                continue
            if len(rx) < 2:
                return
            cmd = rx[1]
            if cmd & HAS_PAYLOAD:
                if len(rx) < 3 or len(rx) < 4 + rx[2]:
                    return
                del rx[: 4 + rx[2]]  # payload requests: not modelled (see the module docstring)
                self.unknown_commands += 1
                continue
            del rx[:2]
            self._request(cmd, now_us)

    def _request(self, cmd: int, now_us: int) -> None:
        spec = self.spec
        if cmd == STOP:
            self.scanning = False
            self.model.stop()
        elif cmd == RESET:
            self.scanning = False
            self.model.stop()
            major, minor = spec.firmware
            banner = f"RP LIDAR System.\r\nFirmware Ver {major}.{minor:02d} - rtm, HW Ver {spec.hardware}\r\n"
            self.send(banner.encode() + f"Model: {spec.model}\r\n".encode(), now_us + 2000)
        elif cmd in (SCAN, FORCE_SCAN):
            self.send(descriptor(5, 1, 0x81), now_us)
            self.scanning = True
            self.model.start(now_us + 1000)
        elif cmd == GET_INFO:
            major, minor = spec.firmware
            payload = bytes([spec.model, minor, major, spec.hardware]) + self.serial_number
            self.send(descriptor(20, 0, 0x04) + payload, now_us)
        elif cmd == GET_HEALTH:
            self.send(descriptor(3, 0, 0x06) + bytes([0, 0, 0]), now_us)
        elif cmd == GET_SAMPLERATE:
            t_std = self.model.sample_us
            payload = t_std.to_bytes(2, "little") + spec.express_sample_us.to_bytes(2, "little")
            self.send(descriptor(4, 0, 0x15) + payload, now_us)
        else:
            self.unknown_commands += 1

    def emit(self, samples: LidarSamples) -> None:
        for t, node in zip(samples.time_us.tolist(), encode_nodes(samples), strict=True):
            self.send(node, t)
