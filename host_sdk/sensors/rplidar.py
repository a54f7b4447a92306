"""RPLIDAR A1 protocol, sans I/O (Slamtec's interface protocol for the A1/A2, standard SCAN mode).

    parser = RPLidarParser()
    port.write(request(GET_HEALTH))
    parser.receive_data(port.read(), t=clock())
    for event in parser.events():        # DeviceInfo, DeviceHealth, SampleRate, LidarScan
        ...

Answers start with a descriptor `A5 5A len(30 bits LE) | mode << 30, type`; a SCAN answer (type
0x81) is followed by 5-byte nodes for as long as the device scans. Each node carries fixed bits (S
and its inverse; a check bit), which is how the parser tells nodes from garbage: a node that breaks
them is counted as a framing error and the parser slides one byte until three valid nodes in a row
line up again (or a new descriptor starts). Those checks are few bits, and a flipped distance bit
passes them all, so a start-of-revolution flag is believed only on a node just past 0 degrees and
at most once per 50 nodes: a corrupted node cannot cut a revolution short. Anything else
unexpected, e.g. the text the A1 prints after RESET, is skipped and counted in
`counters.bytes_discarded`. Nothing here raises on input.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from host_sdk.sensors.scan import DeviceHealth, DeviceInfo, LidarParserBase, LidarScan, point_times
from protocol.sensors import LidarSpec, device

SYNC = 0xA5
STOP, RESET, SCAN, FORCE_SCAN = 0x25, 0x40, 0x20, 0x21
GET_INFO, GET_HEALTH, GET_SAMPLERATE = 0x50, 0x52, 0x59
TYPE_INFO, TYPE_HEALTH, TYPE_SAMPLERATE, TYPE_SCAN = 0x04, 0x06, 0x15, 0x81
START_WITHIN_DEG = 10.0
"""A start-of-revolution node is believed only this close after 0 degrees..."""
MIN_REVOLUTION_NODES = 50
"""... and this many nodes after the last one (a revolution at 10 Hz has 200)."""
RESYNC_NODES = 3
"""Valid nodes in a row that end a resynchronisation after a framing error."""


def request(cmd: int, payload: bytes = b"") -> bytes:
    """A request packet: `A5 cmd`, or with a payload `A5 cmd size payload checksum` (XOR)."""
    if not payload:
        return bytes([SYNC, cmd])
    body = bytes([SYNC, cmd | 0x80, len(payload)]) + payload
    check = 0
    for b in body:
        check ^= b
    return body + bytes([check])


@dataclass(frozen=True, slots=True)
class SampleRate:
    standard_us: int
    express_us: int


Event = DeviceInfo | DeviceHealth | SampleRate | LidarScan


class RPLidarParser(LidarParserBase):
    """Bytes in, events out. `receive_data(data, t)`: `t` is when `data` finished arriving. The
    node period comes from GET_SAMPLERATE once answered."""

    def __init__(self, spec: LidarSpec | None = None) -> None:
        super().__init__(spec or _spec("rplidar-a1"))
        self._resyncing = False
        self._node_count = 0
        self._last_start = -MIN_REVOLUTION_NODES

    def receive_data(self, data: bytes, t: float = 0.0) -> None:
        self.counters.bytes_received += len(data)
        self._buf += data
        buf = self._buf
        while buf:
            if self._answer is not None:
                if not self._take_answer():
                    return
            elif self._streaming:
                progress = self._nodes(t)
                if progress is None:
                    return
                if not progress and not self._descriptor():
                    return
            elif not self._descriptor():
                return

    # -- descriptors and single answers ---------------------------------------------------------
    def _descriptor(self) -> bool:
        """Consume a descriptor (or skip a byte of garbage). False: need more bytes."""
        buf = self._buf
        at = buf.find(b"\xa5\x5a")
        if at < 0:
            keep = 1 if buf[-1] == SYNC else 0
            self._discard(len(buf) - keep)
            return False
        if at:
            self._discard(at)
        if len(buf) < 7:
            return False
        word = int.from_bytes(buf[2:6], "little")
        length, mode, type_ = word & 0x3FFFFFFF, word >> 30, buf[6]
        known = {TYPE_INFO: 20, TYPE_HEALTH: 3, TYPE_SAMPLERATE: 4, TYPE_SCAN: 5}
        if known.get(type_) != length or (mode == 1) != (type_ == TYPE_SCAN):
            self.counters.framing_errors += 1
            self._discard(1)
            return True
        del buf[:7]
        self.counters.descriptors += 1
        if type_ == TYPE_SCAN:
            self._streaming = True
        else:
            self._answer = (type_, length)
        return True

    def _single(self, type_: int, body: bytes) -> None:
        if type_ == TYPE_INFO:
            self._events.append(DeviceInfo(body[0], (body[2], body[1]), body[3], body[4:20].hex().upper()))
        elif type_ == TYPE_HEALTH:
            self._events.append(DeviceHealth(body[0], int.from_bytes(body[1:3], "little")))
        else:
            std, exp = int.from_bytes(body[0:2], "little"), int.from_bytes(body[2:4], "little")
            if std > 0:
                self.sample_period_s = std / 1e6
            self._events.append(SampleRate(std, exp))

    # -- the node stream ----------------------------------------------------------------------------
    def _nodes(self, t: float) -> bool | None:
        """Decode the valid nodes at the head of the buffer (vectorised). None: need more bytes;
        False: the head is a new descriptor (the caller reads it).

        A node is valid when S and not-S differ, the check bit is set and the angle is under 360
        degrees. Those are few bits, so after a framing error the parser takes nodes again only
        where RESYNC_NODES valid ones follow each other (a byte off, a node passes by chance)."""
        buf = self._buf
        whole = len(buf) // 5
        need = RESYNC_NODES if self._resyncing else 1
        if whole < need:
            return False if buf[:2] == b"\xa5\x5a" and len(buf) >= 2 else None
        raw = np.frombuffer(bytes(buf[: whole * 5]), dtype=np.uint8).reshape(whole, 5)
        angle_q6 = (raw[:, 1].astype(np.int64) >> 1) | (raw[:, 2].astype(np.int64) << 7)
        ok = (((raw[:, 0] ^ (raw[:, 0] >> 1)) & 1) == 1) & ((raw[:, 1] & 1) == 1) & (angle_q6 < 360 * 64)
        good = whole if ok.all() else int(np.argmin(ok))
        if good < need:
            if buf[0] == SYNC and buf[1] == 0x5A:
                return False  # a new descriptor: let the caller read it
            if not self._resyncing:
                self.counters.framing_errors += 1
                self._resyncing = True
            self._discard(1)
            return True
        self._resyncing = False
        nodes = raw[:good].astype(np.int64)
        # A node goes on the wire when measured; by t every byte from the last node begun had arrived.
        last = (len(buf) + 4) // 5 - 1 if good == whole else good - 1
        self.arrival.period_s = self.sample_period_s
        self.arrival.bound(last, t, len(buf) - 5 * last)
        del buf[: good * 5]
        # Nodes still in the buffer arrived at t as well: each decoded node is that much earlier.
        later = len(buf) // 5
        times = point_times(t, good + later, self.sample_period_s)[:good]
        measured = self.arrival.times(good)
        angle = angle_q6[:good] / 64.0
        dist = (nodes[:, 3] | (nodes[:, 4] << 8)) / 4.0
        # A revolution starts just past 0 degrees (nodes are under 2 degrees apart at any scan rate),
        # at most once per MIN_REVOLUTION_NODES: a start flag elsewhere is a corrupted node's.
        start = (nodes[:, 0] & 1).astype(bool)
        for i in np.flatnonzero(start).tolist():
            index = self._node_count + i
            if angle[i] < START_WITHIN_DEG and index - self._last_start >= MIN_REVOLUTION_NODES:
                self._last_start = index
            else:
                start[i] = False
                self.counters.framing_errors += 1
        self._node_count += good
        self._points(angle, dist, nodes[:, 0] >> 2, times, start, measured=measured)
        return True


def _spec(name: str) -> LidarSpec:
    spec = device(name, "lidar")
    assert isinstance(spec, LidarSpec)
    return spec
