"""The YDLIDAR F4 as its serial port shows it (EAI's development manual and YDLidar-SDK protocol doc).

Commands are two bytes, `A5 cmd`; answers start with the same 7-byte descriptor as the RPLIDAR's
(`A5 5A len(30 bits) | mode << 30, type`).

| command | answer |
|---|---|
| `A5 60` start scan | `A5 5A 05 00 00 40 81`, then sample packets until stopped |
| `A5 65` stop | none |
| `A5 90` device info | type 04, 20 bytes: model, firmware (u16: major low byte, minor high), hardware, serial[16] |
| `A5 91`, `A5 92` health | type 06, 3 bytes: status (0 ok), error code u16 (the F4 manuals say 91, the SDK sends 92) |
| `A5 0D` get scan frequency, `A5 09/0A/0B/0C` +0.1/-0.1/+1/-1 Hz | type 04, u32: frequency * 100 |
| `A5 D1` get ranging frequency | type 04, 1 byte: 0 (4 kHz) |
| `A5 80` restart | none |

A sample packet: `AA 55` (0x55AA LE), CT, LSN, FSA u16, LSA u16, CS u16, then LSN samples of u16
(distance in mm * 4). CT bit 0 marks the zero packet (one sample, the first of a revolution) whose
CT >> 1 is the scan frequency * 10; FSA/LSA are `angle_q6 << 1 | 1` of the first and last sample;
CS is the XOR of the 16-bit words PH, FSA, every sample, `LSN << 8 | CT` and LSA. A triangulation
lidar's beam leaves off its rotor angle by a range-dependent angle the host corrects for (the SDK's
"second-level analysis"); the model casts each beam where the corrected angle points.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from emulator.rng import Streams
from emulator.sensors.lidar import LidarModel, LidarSamples
from emulator.sensors.rplidar import descriptor
from emulator.sensors.serial import LidarDevice
from protocol.sensors import LidarSpec, Mount

PACKET_SAMPLES = 40
"""Samples in a normal packet (the SDK's TrianglePackageDataSize)."""
HEADER = 0x55AA


def angle_correction_deg(range_mm: NDArray[np.float64]) -> NDArray[np.float64]:
    """The triangulation lidars' second-level angle correction (0 where there is no range)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        corr = np.degrees(np.arctan(21.8 * (155.3 - range_mm) / (155.3 * range_mm)))
    return np.where(range_mm > 0, corr, 0.0)


def encode_packet(ct: int, angles_deg: NDArray[np.float64], range_m: NDArray[np.float64]) -> bytes:
    """One sample packet (the header, then 2-byte samples)."""
    q6 = np.rint(np.asarray(angles_deg) * 64).astype(np.int64) % (360 * 64)
    fsa, lsa = int(q6[0]) << 1 | 1, int(q6[-1]) << 1 | 1
    si = np.clip(np.rint(np.asarray(range_m) * 4000), 0, 0xFFFF).astype(np.uint16)
    lsn = int(si.shape[0])
    cs = HEADER ^ fsa ^ lsa ^ (lsn << 8 | ct)
    cs ^= int(np.bitwise_xor.reduce(si)) if lsn else 0
    head = bytes([0xAA, 0x55, ct, lsn]) + fsa.to_bytes(2, "little") + lsa.to_bytes(2, "little")
    return head + cs.to_bytes(2, "little") + si.astype("<u2").tobytes()


class YDLidarF4(LidarDevice):
    def __init__(self, spec: LidarSpec, mount: Mount, streams: Streams, log: Callable[[int, str, str], None]) -> None:
        super().__init__(spec, LidarModel(spec, mount, None, beam_offset=angle_correction_deg), streams, log)
        self._pending: list[tuple[int, float, float]] = []  # (time, angle, range) not yet sent
        self.serial_number = bytes(int(d) for d in self.rng.integers(0, 10, 16))

    def on_bytes(self, data: bytes, now_us: int) -> None:
        rx = self._rx
        rx += data
        while len(rx) >= 2:
            if rx[0] != 0xA5:
                del rx[0]
                continue
            cmd = rx[1]
            del rx[:2]
            self._command(cmd, now_us)
        if rx and rx[0] != 0xA5:
            rx.clear()

    def _command(self, cmd: int, now_us: int) -> None:
        spec = self.spec
        if cmd == 0x60:
            self.send(descriptor(5, 1, 0x81), now_us)
            self.scanning = True
            self._pending.clear()
            self.model.start(now_us + 1000)
        elif cmd in (0x65, 0x00, 0x80):
            self.scanning = False
            self.model.stop()
            self._pending.clear()
        elif cmd == 0x90:
            major, minor = spec.firmware
            payload = bytes([spec.model, major, minor, spec.hardware]) + self.serial_number
            self.send(descriptor(20, 0, 0x04) + payload, now_us)
        elif cmd in (0x91, 0x92):
            self.send(descriptor(3, 0, 0x06) + bytes(3), now_us)
        elif cmd in (0x09, 0x0A, 0x0B, 0x0C, 0x0D):
            step = {0x09: 0.1, 0x0A: -0.1, 0x0B: 1.0, 0x0C: -1.0, 0x0D: 0.0}[cmd]
            self.model.set_scan_hz(round(self.model.scan_hz + step, 2))
            self.send(descriptor(4, 0, 0x04) + round(self.model.scan_hz * 100).to_bytes(4, "little"), now_us)
        elif cmd == 0xD1:
            self.send(descriptor(1, 0, 0x04) + b"\x00", now_us)
        else:
            self.unknown_commands += 1

    def emit(self, samples: LidarSamples) -> None:
        pending = self._pending
        rows = zip(samples.time_us.tolist(), samples.angle_deg.tolist(), samples.range_m.tolist(), strict=True)
        for (t, a, r), first in zip(rows, samples.start.tolist(), strict=True):
            if first:
                self._flush()
                ct = (round(self.model.scan_hz * 10) & 0x7F) << 1 | 1
                self.send(encode_packet(ct, np.array([a]), np.array([r])), t)
                continue
            pending.append((t, a, r))
            if len(pending) == PACKET_SAMPLES:
                self._flush()

    def _flush(self) -> None:
        if not self._pending:
            return
        times, angles, ranges = zip(*self._pending, strict=True)
        # Rotor angles are continuous within a packet; the last may have wrapped past 360.
        unwrapped = np.unwrap(np.radians(np.array(angles)))
        self.send(encode_packet(0, np.degrees(unwrapped) % 360.0, np.array(ranges)), times[-1])
        self._pending.clear()
