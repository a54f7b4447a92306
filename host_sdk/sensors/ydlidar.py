"""YDLIDAR F4 protocol, sans I/O (YDLidar-SDK communication protocol; EAI's development manual).

    parser = YDLidarParser()
    port.write(command(START_SCAN))
    parser.receive_data(port.read(), t=clock())
    for event in parser.events():        # DeviceInfo, DeviceHealth, ScanFrequency, LidarScan
        ...

Answers start with the descriptor `A5 5A len | mode << 30, type`; while scanning, packets
`AA 55 CT LSN FSA LSA CS S1..Sn` follow, checked with their 16-bit XOR (CS). A packet that fails
its check, or has an impossible length, is counted and the parser slides one byte to find the next
header. Angles: FSA/LSA (`q6 << 1 | 1`) give the first and last sample's angle, the others are
interpolated; with `angle_correction` (triangulation lidars, the default) each sample gets the
second-level correction `atan(21.8 * (155.3 - d) / (155.3 * d))` for its distance d in mm. Nothing
here raises on input.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from host_sdk.sensors.rplidar import _spec
from host_sdk.sensors.scan import DeviceHealth, DeviceInfo, LidarParserBase, LidarScan, point_times
from protocol.sensors import LidarSpec

START_SCAN, STOP_SCAN, GET_INFO, GET_HEALTH, RESTART = 0x60, 0x65, 0x90, 0x92, 0x80
GET_FREQUENCY, FREQ_UP_TENTH, FREQ_DOWN_TENTH, FREQ_UP, FREQ_DOWN = 0x0D, 0x09, 0x0A, 0x0B, 0x0C
MAX_SAMPLES = 128
"""More samples than this in one packet is a framing error (the F4 sends at most 40)."""


def command(cmd: int) -> bytes:
    return bytes([0xA5, cmd])


@dataclass(frozen=True, slots=True)
class ScanFrequency:
    hz: float


Event = DeviceInfo | DeviceHealth | ScanFrequency | LidarScan


class YDLidarParser(LidarParserBase):
    def __init__(self, spec: LidarSpec | None = None, *, angle_correction: bool = True) -> None:
        super().__init__(spec or _spec("ydlidar-f4"))
        self.angle_correction = angle_correction
        self.scan_hz: float | None = None
        """The scan frequency the last zero packet reported (None until one does)."""

    def receive_data(self, data: bytes, t: float = 0.0) -> None:
        self.counters.bytes_received += len(data)
        buf = self._buf
        buf += data
        while buf:
            if self._answer is not None:
                if not self._take_answer():
                    return
                continue
            at_packet = buf.find(b"\xaa\x55") if self._streaming else -1
            at_desc = buf.find(b"\xa5\x5a")
            heads = [a for a in (at_packet, at_desc) if a >= 0]
            if not heads:
                self._discard(len(buf) - (1 if buf[-1] in (0xAA, 0xA5) else 0))
                return
            at = min(heads)
            self._discard(at)
            done = self._packet(t) if at == at_packet else self._descriptor()
            if done is None:
                return

    def _descriptor(self) -> bool | None:
        buf = self._buf
        if len(buf) < 7:
            return None
        word = int.from_bytes(buf[2:6], "little")
        length, mode, type_ = word & 0x3FFFFFFF, word >> 30, buf[6]
        if type_ == 0x81 and mode == 1:
            self._streaming = True
        elif mode == 0 and type_ in (0x04, 0x06) and 0 < length <= 64:
            self._answer = (type_, length)
        else:
            self.counters.framing_errors += 1
            self._discard(1)
            return False
        del buf[:7]
        self.counters.descriptors += 1
        return True

    def _single(self, type_: int, body: bytes) -> None:
        if type_ == 0x06 and len(body) == 3:
            self._events.append(DeviceHealth(body[0], int.from_bytes(body[1:3], "little")))
        elif type_ == 0x04 and len(body) == 20:
            self._events.append(DeviceInfo(body[0], (body[1], body[2]), body[3], body[4:20].hex().upper()))
        elif type_ == 0x04 and len(body) == 4:
            self._events.append(ScanFrequency(int.from_bytes(body, "little") / 100))

    def _packet(self, t: float) -> bool | None:
        buf = self._buf
        if len(buf) < 4:
            return None
        ct, lsn = buf[2], buf[3]
        if lsn == 0 or lsn > MAX_SAMPLES or ((ct & 1) and lsn != 1):
            self.counters.framing_errors += 1
            self._discard(1)
            return False
        # The F4 sends a packet once its last sample is measured (the header holds that sample's
        # angle and the checksum): every byte from the packet's first on had arrived by t.
        self.arrival.bound(lsn - 1, t, len(buf))
        size = 10 + 2 * lsn
        if len(buf) < size:
            return None
        words = np.frombuffer(bytes(buf[:size]), dtype="<u2").astype(np.int64)
        fsa, lsa, cs, samples = int(words[2]), int(words[3]), int(words[4]), words[5:]
        check = 0x55AA ^ fsa ^ lsa ^ (lsn << 8 | ct) ^ int(np.bitwise_xor.reduce(samples))
        if check != cs or not (fsa & 1 and lsa & 1):
            self.counters.checksum_errors += 1
            self._discard(1)
            return False
        del buf[:size]
        self._decode(ct, fsa, lsa, samples, t)
        return True

    def _decode(self, ct: int, fsa: int, lsa: int, samples: np.ndarray, t: float) -> None:
        lsn = samples.shape[0]
        first, last = (fsa >> 1) / 64.0, (lsa >> 1) / 64.0
        diff = last - first + (360.0 if last < first else 0.0)
        angle = first + (diff / (lsn - 1) * np.arange(lsn) if lsn > 1 else np.zeros(1))
        dist = samples / 4.0
        if self.angle_correction:
            with np.errstate(divide="ignore", invalid="ignore"):
                corr = np.degrees(np.arctan(21.8 * (155.3 - dist) / (155.3 * dist)))
            angle = angle + np.where(dist > 0, corr, 0.0)
        angle = np.mod(angle, 360.0)
        start = np.zeros(lsn, dtype=bool)
        if ct & 1:
            start[0] = True
            if ct >> 1:
                self.scan_hz = (ct >> 1) / 10
        later = self._pending_samples()
        times = point_times(t, lsn + later, self.sample_period_s)[:lsn]
        measured = self.arrival.times(lsn)
        self._points(angle, dist, np.zeros(lsn, dtype=np.int64), times, start, measured=measured)

    def _pending_samples(self) -> int:
        """Samples of whole packets still in the buffer (they arrived at the same t)."""
        return max(0, (len(self._buf) - 10) // 2) if len(self._buf) > 10 else 0
