"""WIT standard protocol (WIT-motion JY901 and its family), sans I/O.

    parser = WitParser()
    parser.receive_data(port.read(), t=clock())
    for event in parser.events():      # Acceleration, AngularVelocity, Angle, Magnetic, Quaternion,
        ...                            # TimePacket, PortStatus, Pressure, GpsPosition, GpsVelocity,
                                       # GpsAccuracy, Registers, and ImuSample

Packets are 11 bytes: `55 TYPE d0..d7 SUM`, SUM the low byte of the sum of the ten before it, the
data four little-endian int16. A packet with a wrong sum or an unknown type is counted and the parser
slides one byte. The module sends its enabled outputs in type order every period; when a type comes
round again the group is complete and an `ImuSample` with everything of that period is emitted.
Units are converted to SI (m/s^2, rad/s, rad); the magnetometer stays in the module's units (mG).

Configuration goes the other way as 5-byte writes `FF AA ADDR DATAL DATAH`: see `unlock()`,
`set_rate()`, `set_outputs()`, `set_baud()`, `calibrate()`, `save()`, `read_registers()`.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass

G = 9.80665
RATES_HZ = {
    0.2: 0x01,
    0.5: 0x02,
    1: 0x03,
    2: 0x04,
    5: 0x05,
    10: 0x06,
    20: 0x07,
    50: 0x08,
    100: 0x09,
    125: 0x0A,
    200: 0x0B,
}
BAUDS = {4800: 1, 9600: 2, 19200: 3, 38400: 4, 57600: 5, 115200: 6, 230400: 7, 460800: 8, 921600: 9}
OUTPUTS = {
    "time": 0x001,
    "acc": 0x002,
    "gyro": 0x004,
    "angle": 0x008,
    "mag": 0x010,
    "port": 0x020,
    "pressure": 0x040,
    "gps": 0x080,
    "velocity": 0x100,
    "quat": 0x200,
    "gsa": 0x400,
}
CALIBRATIONS = {"normal": 0, "accel": 1, "mag_exit": 0, "height": 3, "heading_zero": 4, "mag": 7, "reference": 8}
SAVE, CALSW, RSW, RRATE, BAUD, AXIS6, READADDR, KEY = 0x00, 0x01, 0x02, 0x03, 0x04, 0x24, 0x27, 0x69
TYPES = range(0x50, 0x5B)


def write(addr: int, value: int) -> bytes:
    """A register write: `FF AA ADDR DATAL DATAH`."""
    return bytes([0xFF, 0xAA, addr & 0xFF, value & 0xFF, value >> 8 & 0xFF])


def unlock() -> bytes:
    """Writes are accepted for 10 s after this (newer firmware; older modules ignore it)."""
    return write(KEY, 0xB588)


def save() -> bytes:
    return write(SAVE, 0)


def restart() -> bytes:
    return write(SAVE, 0xFF)


def set_rate(hz: float) -> bytes:
    code = RATES_HZ.get(hz)
    if code is None:
        raise ValueError(f"rate_hz = {hz!r} is not allowed: one of {', '.join(f'{r:g}' for r in RATES_HZ)}")
    return write(RRATE, code)


def set_outputs(*names: str) -> bytes:
    unknown = [n for n in names if n not in OUTPUTS]
    if unknown:
        raise ValueError(f"output {unknown[0]!r} is not allowed: one of {', '.join(OUTPUTS)}")
    return write(RSW, sum(OUTPUTS[n] for n in set(names)))


def set_baud(baud: int) -> bytes:
    if baud not in BAUDS:
        raise ValueError(f"baud = {baud!r} is not allowed: one of {', '.join(map(str, BAUDS))}")
    return write(BAUD, BAUDS[baud])


def calibrate(mode: str) -> bytes:
    """CALSW: normal (end), accel (level and still), heading_zero, mag (then normal), height, reference."""
    if mode not in CALIBRATIONS:
        raise ValueError(f"calibration {mode!r} is not allowed: one of {', '.join(CALIBRATIONS)}")
    return write(CALSW, CALIBRATIONS[mode])


def set_axis6(six_axis: bool) -> bytes:
    """6-axis mode (no magnetometer in the yaw) or 9-axis."""
    return write(AXIS6, int(six_axis))


def read_registers(addr: int) -> bytes:
    """Ask for 4 registers from `addr`: the module answers with a `Registers` packet (0x5F)."""
    return write(READADDR, addr)


@dataclass(frozen=True, slots=True)
class TimePacket:
    t: float
    year: int
    month: int
    day: int
    hour: int
    minute: int
    second: int
    millisecond: int


@dataclass(frozen=True, slots=True)
class Acceleration:
    t: float
    xyz: tuple[float, float, float]
    """m/s^2."""
    temperature_c: float


@dataclass(frozen=True, slots=True)
class AngularVelocity:
    t: float
    xyz: tuple[float, float, float]
    """rad/s."""
    temperature_c: float


@dataclass(frozen=True, slots=True)
class Angle:
    t: float
    roll: float
    pitch: float
    yaw: float
    """rad, -pi..pi."""
    version: int


@dataclass(frozen=True, slots=True)
class Magnetic:
    t: float
    xyz: tuple[int, int, int]
    """Module units (mG)."""
    temperature_c: float


@dataclass(frozen=True, slots=True)
class Quaternion:
    t: float
    wxyz: tuple[float, float, float, float]


@dataclass(frozen=True, slots=True)
class Pressure:
    t: float
    pascal: int
    height_m: float


@dataclass(frozen=True, slots=True)
class GpsPosition:
    t: float
    longitude_deg: float
    latitude_deg: float
    """Decimal degrees, from the module's ddmm.mmmmm integers."""


@dataclass(frozen=True, slots=True)
class GpsVelocity:
    t: float
    height_m: float
    heading_deg: float
    speed_km_h: float


@dataclass(frozen=True, slots=True)
class GpsAccuracy:
    t: float
    satellites: int
    pdop: float
    hdop: float
    vdop: float


@dataclass(frozen=True, slots=True)
class PortStatus:
    t: float
    d: tuple[int, int, int, int]


@dataclass(frozen=True, slots=True)
class Registers:
    t: float
    values: tuple[int, int, int, int]
    """Raw 16-bit register values from the address that was asked for."""


@dataclass(frozen=True, slots=True)
class OtherPacket:
    """A valid packet of a type this parser does not decode (pressure, GPS...)."""

    t: float
    type: int
    data: bytes


Packet = (
    TimePacket
    | Acceleration
    | AngularVelocity
    | Angle
    | Magnetic
    | Quaternion
    | PortStatus
    | Registers
    | Pressure
    | GpsPosition
    | GpsVelocity
    | GpsAccuracy
    | OtherPacket
)


@dataclass(frozen=True, slots=True)
class ImuSample:
    """One output period of the module: whatever it was set to send (None: not enabled)."""

    t: float
    accel: tuple[float, float, float] | None
    gyro: tuple[float, float, float] | None
    angle: tuple[float, float, float] | None
    """roll, pitch, yaw in rad."""
    mag: tuple[int, int, int] | None
    quaternion: tuple[float, float, float, float] | None
    temperature_c: float | None


@dataclass(slots=True)
class WitCounters:
    bytes_received: int = 0
    bytes_discarded: int = 0
    checksum_errors: int = 0
    packets: int = 0
    samples: int = 0


def decode(type_: int, data: bytes, t: float) -> Packet:
    """One packet's 8 data bytes."""
    a, b, c, d = struct.unpack("<4h", data)
    if type_ == 0x50:
        return TimePacket(t, 2000 + data[0], data[1], data[2], data[3], data[4], data[5], data[6] | data[7] << 8)
    if type_ == 0x51:
        return Acceleration(t, (a / 32768 * 16 * G, b / 32768 * 16 * G, c / 32768 * 16 * G), d / 100)
    if type_ == 0x52:
        k = math.radians(2000) / 32768
        return AngularVelocity(t, (a * k, b * k, c * k), d / 100)
    if type_ == 0x53:
        k = math.pi / 32768
        return Angle(t, a * k, b * k, c * k, d & 0xFFFF)
    if type_ == 0x54:
        return Magnetic(t, (a, b, c), d / 100)
    if type_ == 0x55:
        return PortStatus(t, (a, b, c, d))
    if type_ == 0x56:
        pa, cm = struct.unpack("<2i", data)
        return Pressure(t, pa, cm / 100)
    if type_ == 0x57:
        lon, lat = struct.unpack("<2i", data)
        return GpsPosition(t, _ddmm(lon), _ddmm(lat))
    if type_ == 0x58:
        height, heading, speed = struct.unpack("<2hi", data)
        return GpsVelocity(t, height / 10, heading / 100, speed / 1000)
    if type_ == 0x5A:
        return GpsAccuracy(t, a, b / 100, c / 100, d / 100)
    if type_ == 0x59:
        return Quaternion(t, (a / 32768, b / 32768, c / 32768, d / 32768))
    if type_ == 0x5F:
        return Registers(t, struct.unpack("<4H", data))
    return OtherPacket(t, type_, data)


def _ddmm(value: int) -> float:
    """ddmm.mmmmm as the module sends it (degrees * 10^7 + minutes * 10^5) in decimal degrees."""
    sign = -1 if value < 0 else 1
    v = abs(value)
    return sign * (v // 10_000_000 + (v % 10_000_000) / 100_000 / 60)


class WitParser:
    def __init__(self) -> None:
        self.counters = WitCounters()
        self._buf = bytearray()
        self._events: list[Packet | ImuSample] = []
        self._group: dict[int, Packet] = {}
        self._last_type = -1

    def events(self) -> list[Packet | ImuSample]:
        out, self._events = self._events, []
        return out

    def receive_data(self, data: bytes, t: float = 0.0) -> None:
        self.counters.bytes_received += len(data)
        buf = self._buf
        buf += data
        while len(buf) >= 11:
            if buf[0] != 0x55 or (buf[1] not in TYPES and buf[1] != 0x5F):
                at = buf.find(0x55, 1)
                self._discard(at if at > 0 else len(buf))
                continue
            if sum(buf[:10]) & 0xFF != buf[10]:
                self.counters.checksum_errors += 1
                self._discard(1)
                continue
            type_ = buf[1]
            packet = decode(type_, bytes(buf[2:10]), t)
            del buf[:11]
            self.counters.packets += 1
            if type_ != 0x5F:
                self._grouped(type_, packet)  # may close the previous period first
            self._events.append(packet)

    def _grouped(self, type_: int, packet: Packet) -> None:
        if type_ <= self._last_type and self._group:
            self._emit()
        self._group[type_] = packet
        self._last_type = type_

    def flush(self) -> ImuSample | None:
        """Emit the group in progress now (e.g. at the end of a recording)."""
        if not self._group:
            return None
        self._emit()
        out = self._events.pop()
        assert isinstance(out, ImuSample)
        return out

    def _emit(self) -> None:
        g = self._group
        acc, gyro, ang = g.get(0x51), g.get(0x52), g.get(0x53)
        mag, quat = g.get(0x54), g.get(0x59)
        first = min(g)
        temp = next((p.temperature_c for p in (acc, gyro, mag) if p is not None), None)  # type: ignore[union-attr]
        self._events.append(
            ImuSample(
                t=g[first].t,
                accel=acc.xyz if isinstance(acc, Acceleration) else None,
                gyro=gyro.xyz if isinstance(gyro, AngularVelocity) else None,
                angle=(ang.roll, ang.pitch, ang.yaw) if isinstance(ang, Angle) else None,
                mag=mag.xyz if isinstance(mag, Magnetic) else None,
                quaternion=quat.wxyz if isinstance(quat, Quaternion) else None,
                temperature_c=temp,
            )
        )
        self.counters.samples += 1
        self._group = {}
        self._last_type = -1

    def _discard(self, n: int) -> None:
        del self._buf[:n]
        self.counters.bytes_discarded += n
