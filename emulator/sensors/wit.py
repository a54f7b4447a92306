"""The JY901 on its serial port: the WIT standard protocol.

Output: 11-byte packets `55 TYPE d0..d7 SUM` (SUM = the low byte of the sum of the first ten), the
data as four little-endian int16. Each enabled output (register RSW) is sent once per period
(register RRATE), in type order:

| type | RSW bit | data (int16 x4) |
|---|---|---|
| 0x50 time | 0x001 | YY MM DD hh mm ss, ms u16 |
| 0x51 acceleration | 0x002 | a / 16 g * 32768 (x, y, z), temperature * 100 |
| 0x52 angular velocity | 0x004 | w / 2000 deg/s * 32768 (x, y, z), temperature * 100 |
| 0x53 angle | 0x008 | roll, pitch, yaw / 180 deg * 32768, version |
| 0x54 magnetic field | 0x010 | H (x, y, z) in mG, temperature * 100 |
| 0x55 port status | 0x020 | D0..D3 (0: nothing is wired) |
| 0x59 quaternion | 0x200 | q0..q3 * 32768 |
| 0x5F register read | | the 4 registers from the address asked for (READADDR) |

Input: 5-byte writes `FF AA ADDR DATAL DATAH`. Writes need the unlock `FF AA 69 88 B5` first (it
holds 10 s); the model handles SAVE (00: save, FF: restart), CALSW (01: 0 normal, 1 accelerometer
calibration, 4 heading zero, 7 magnetic calibration), RSW (02), RRATE (03: 1..0x0B = 0.2..200 Hz,
0x0C once, 0x0D stop), BAUD (04: 1..9 = 4800..921600; paces the emulated line), AXIS6 (24: 1 =
6-axis, no compass) and READADDR (27). Packets that do not fit the line (more outputs than the baud
carries at the rate) are dropped whole, as the module's UART buffer does; `packets_dropped` counts.
"""

from __future__ import annotations

import struct
from collections.abc import Callable

from emulator.rng import Streams
from emulator.sensors.imu import ImuModel, ImuSample, Motion
from emulator.sensors.lidar import PoseAt
from emulator.sensors.serial import SerialSensor
from emulator.world.scene import Scene
from protocol.sensors import ImuSpec, Mount

RATES_HZ = {1: 0.2, 2: 0.5, 3: 1, 4: 2, 5: 5, 6: 10, 7: 20, 8: 50, 9: 100, 0x0A: 125, 0x0B: 200}
BAUDS = {1: 4800, 2: 9600, 3: 19200, 4: 38400, 5: 57600, 6: 115200, 7: 230400, 8: 460800, 9: 921600}
OUTPUT_BITS = {"time": 0x001, "acc": 0x002, "gyro": 0x004, "angle": 0x008, "mag": 0x010, "port": 0x020, "quat": 0x200}
SAVE, CALSW, RSW, RRATE, BAUD, AXIS6, READADDR, KEY = 0x00, 0x01, 0x02, 0x03, 0x04, 0x24, 0x27, 0x69
UNLOCK = 0xB588
VERSION = 0x0F9A
MAX_BACKLOG_US = 10_000
"""Packets wait at most this long for the UART; beyond it they are dropped."""


def packet(type_: int, data: bytes) -> bytes:
    body = bytes([0x55, type_]) + data
    return body + bytes([sum(body) & 0xFF])


def _i16(value: float) -> int:
    return max(-32768, min(32767, round(value)))


def _words(*values: float) -> bytes:
    return struct.pack("<4h", *(_i16(v) for v in values))


class JY901(SerialSensor):
    kind = "imu"

    def __init__(
        self, spec: ImuSpec, mount: Mount, streams: Streams, log: Callable[[int, str, str], None], motion: Motion
    ) -> None:
        super().__init__("imu", spec.baud, streams, log)
        self.spec = spec
        self.model = ImuModel(spec, self.rng, mount.yaw_rad)
        self.motion = motion
        self.regs: dict[int, int] = {RSW: sum(OUTPUT_BITS[o] for o in spec.outputs), AXIS6: 0}
        self.regs[RRATE] = next(code for code, hz in RATES_HZ.items() if hz == spec.rate_hz)
        self.regs[BAUD] = next(code for code, b in BAUDS.items() if b == spec.baud)
        self.next_us: int | None = 0
        self.unlocked_until = -1
        self.packets_dropped = 0
        self.writes_locked = 0
        self.last: ImuSample | None = None
        self._rx = bytearray()

    @property
    def rate_hz(self) -> float:
        return float(RATES_HZ.get(self.regs[RRATE], 0.0))

    def on_bytes(self, data: bytes, now_us: int) -> None:
        rx = self._rx
        rx += data
        while len(rx) >= 5:
            if rx[0] != 0xFF or rx[1] != 0xAA:
                del rx[0]
                continue
            addr, value = rx[2], rx[3] | rx[4] << 8
            del rx[:5]
            self._write(addr, value, now_us)

    def _write(self, addr: int, value: int, now_us: int) -> None:
        if addr == KEY:
            if value == UNLOCK:
                self.unlocked_until = now_us + 10_000_000
            return
        if addr == READADDR:
            self._read_registers(value, now_us)
            return
        if now_us > self.unlocked_until:
            self.writes_locked += 1
            return
        if addr == CALSW:
            if value == 1:
                self.model.calibrate_accel()
            elif value == 4:
                self.model.zero_heading()
            elif value == 0 and self.regs.get(CALSW) == 7:
                self.model.calibrate_mag()
        elif addr == RRATE:
            if value == 0x0C:
                self._emit(now_us)  # one set of packets, then silence
                value = 0x0D
            self.next_us = None if value not in RATES_HZ else now_us
        elif addr == BAUD and value in BAUDS:
            self.tx.baud = BAUDS[value]
        elif addr == AXIS6:
            self.model.axis6 = value == 1
        elif addr == SAVE and value == 0xFF:
            self.next_us = now_us + 500_000  # restarting: silent for a while
        self.regs[addr] = value

    def _read_registers(self, start: int, now_us: int) -> None:
        values = [self._register(start + i) for i in range(4)]
        self.send(packet(0x5F, struct.pack("<4H", *(v & 0xFFFF for v in values))), now_us)

    def _register(self, addr: int) -> int:
        s = self.last
        if addr == 0x2E:
            return VERSION
        if s is not None and 0x34 <= addr <= 0x40:
            table = [
                *(a / 16 * 32768 for a in s.accel_g),
                *(w / 2000 * 32768 for w in s.gyro_dps),
                *s.mag_mg,
                *(a / 180 * 32768 for a in s.angle_deg),
                s.temperature_c * 100,
            ]
            return _i16(table[addr - 0x34])
        if s is not None and 0x51 <= addr <= 0x54:
            return _i16(s.quaternion[addr - 0x51] * 32768)
        return self.regs.get(addr, 0)

    def update(self, scene: Scene, until_us: int, pose_at: PoseAt) -> None:
        while self.next_us is not None and self.next_us < until_us:
            t = self.next_us
            self._emit(t)
            rate = self.rate_hz
            self.next_us = t + round(1e6 / rate) if rate > 0 and self.regs[RRATE] != 0x0D else None

    def _emit(self, t: int) -> None:
        s = self.model.sample(t, self.motion)
        self.last = s
        if self.tx.backlog_us(t) > MAX_BACKLOG_US:
            self.packets_dropped += 1
            return
        self.send(self.encode(s), t)

    def encode(self, s: ImuSample) -> bytes:
        rsw = self.regs[RSW]
        temp = s.temperature_c * 100
        out = []
        if rsw & 0x001:
            ms = s.time_us // 1000
            sec, ms = divmod(ms, 1000)
            minute, sec = divmod(sec, 60)
            hour, minute = divmod(minute, 60)
            out.append(packet(0x50, bytes([25, 1, 1 + hour // 24, hour % 24, minute, sec]) + struct.pack("<H", ms)))
        if rsw & 0x002:
            out.append(packet(0x51, _words(*(a / 16 * 32768 for a in s.accel_g), temp)))
        if rsw & 0x004:
            out.append(packet(0x52, _words(*(w / 2000 * 32768 for w in s.gyro_dps), temp)))
        if rsw & 0x008:
            out.append(packet(0x53, _words(*(a / 180 * 32768 for a in s.angle_deg), VERSION)))
        if rsw & 0x010:
            out.append(packet(0x54, _words(*s.mag_mg, temp)))
        if rsw & 0x020:
            out.append(packet(0x55, bytes(8)))
        if rsw & 0x200:
            out.append(packet(0x59, _words(*(q * 32768 for q in s.quaternion))))
        return b"".join(out)
