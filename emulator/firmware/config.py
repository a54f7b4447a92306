"""Configuration and PID gains: validation, and their EEPROM image (the same layout as the C++ core).

EEPROM layout (docs/firmware.md):
    0x000   boot counter, u32 little-endian (incremented at every boot)
    0x010   image, 81 bytes:
            'R' 'L', image version, SET_CONFIG's CRC_EXTRA, SET_PID's CRC_EXTRA (a firmware built from
            a spec that changed either layout reads the image as another version),
            the SET_CONFIG payload (40 bytes), one SET_PID payload per wheel (17 bytes each),
            CRC-16/CCITT-FALSE of all of the above, little-endian.
"""

from __future__ import annotations

import enum
import math
import struct
from dataclasses import dataclass

from protocol.codec.crc import crc16
from protocol.codec.message import FieldInfo, Message
from protocol.generated.constants import PID_ALL_WHEELS, WHEEL_COUNT
from protocol.generated.messages import SetConfig, SetPid
from protocol.generated.oracle import PAYLOADS

BOOT_COUNTER_ADDR = 0x000
IMAGE_ADDR = 0x010
IMAGE_VERSION = 1
_HEADER = bytes((ord("R"), ord("L"), IMAGE_VERSION, SetConfig.CRC_EXTRA, SetPid.CRC_EXTRA))
CONFIG_SIZE = SetConfig.PAYLOAD_SIZE
IMAGE_SIZE = len(_HEADER) + CONFIG_SIZE + WHEEL_COUNT * SetPid.PAYLOAD_SIZE + 2
_F32 = struct.Struct("<f")


class LoadResult(enum.Enum):
    OK = "ok"
    NO_IMAGE = "config: no EEPROM image for this version, using defaults"
    BAD_CRC = "config: EEPROM CRC error, using defaults"
    INVALID = "config: EEPROM values invalid, using defaults"
    """Each failure's value is the LOG(WARN) text the firmware sends after the boot IDENTITY."""


def f32(x: float) -> float:
    """`x` as the MCU stores it: IEEE-754 single precision."""
    value: float = _F32.unpack(_F32.pack(x))[0]
    return value


@dataclass(frozen=True, slots=True)
class Gains:
    kp: float
    ki: float
    kd: float
    kf: float
    ks: float = 0.0

    @classmethod
    def of(cls, pid: SetPid) -> Gains:
        return cls(f32(pid.kp), f32(pid.ki), f32(pid.kd), f32(pid.kf), f32(pid.ks))


def first_out_of_range(msg: Message) -> int | None:
    """Index of the first field outside its spec range (the firmware's generated check_ranges),
    or None. NaN and infinity are out of range."""
    for index, info in enumerate(msg.FIELDS):
        if not _in_range(info, getattr(msg, info.name)):
            return index
    return None


def first_refused_field(cls: type[Message], payload: bytes) -> int | None:
    """Index of the first field of a payload the decoder refused (a value its type does not
    define) that is outside its spec range or undefined: what the firmware's check_ranges() names
    for a reliable request whose values only it checks. None if every field is allowed."""
    raw = PAYLOADS[cls.MSG_ID].parse(payload)
    for index, info in enumerate(cls.FIELDS):
        value = raw[info.name]
        if info.kind == "str":
            value = bytes(value)
            ok = value.isascii()
        elif info.kind in ("enum", "flags"):
            ok = all(_defined(info, v) for v in (value if info.count is not None else [value]))
        else:
            ok = _in_range(info, list(value) if info.count is not None else value)
        if not ok:
            return index
    return None


def _defined(info: FieldInfo, value: int) -> bool:
    if info.kind == "flags":
        return not value & ~int(info.hi)
    return info.enum is not None and value in {int(m) for m in info.enum}


def _in_range(info: FieldInfo, value: object) -> bool:
    if info.count is not None and isinstance(value, (tuple, list)):
        return all(_in_range(FieldInfo(info.name, info.wire_type, info.kind, info.lo, info.hi), v) for v in value)
    if info.kind in ("str", "bytes", "enum", "flags"):
        return True  # the decoder already refused anything these cannot hold
    if not isinstance(value, (int, float)):
        return False
    if isinstance(value, float) and not math.isfinite(value):
        return False
    return info.lo <= value <= info.hi


def _index(name: str) -> int:
    return next(i for i, f in enumerate(SetConfig.FIELDS) if f.name == name)


def first_inconsistent(c: SetConfig) -> int | None:
    """SET_CONFIG consistency rules of docs/control.md 2; the lowest field index of the first
    rule that fails (the rules are checked in the order they are written there), or None."""
    rules: list[tuple[bool, str, str]] = [
        (c.steering_min_cdeg <= c.steering_center_cdeg, "steering_center_cdeg", "steering_min_cdeg"),
        (c.steering_center_cdeg <= c.steering_max_cdeg, "steering_center_cdeg", "steering_max_cdeg"),
        (c.servo_min_us < c.servo_max_us, "servo_min_us", "servo_max_us"),
        (c.esc_min_us < c.esc_neutral_us, "esc_min_us", "esc_neutral_us"),
        (c.esc_neutral_us < c.esc_max_us, "esc_neutral_us", "esc_max_us"),
    ]
    for ok, a, b in rules:
        if not ok:
            return min(_index(a), _index(b))
    return None


def pid_wheel_ok(wheel: int) -> bool:
    return 0 <= wheel < WHEEL_COUNT or wheel == PID_ALL_WHEELS


def encode_image(config: SetConfig, gains: list[Gains]) -> bytes:
    body = _HEADER + config.pack()
    for wheel, g in enumerate(gains):
        body += SetPid(wheel, g.kp, g.ki, g.kd, g.kf, g.ks).pack()
    return body + crc16(body).to_bytes(2, "little")


def decode_image(raw: bytes) -> tuple[LoadResult, SetConfig | None, list[Gains] | None]:
    """What a boot makes of the EEPROM image: (OK, config, gains) or (the failure, None, None)."""
    if len(raw) != IMAGE_SIZE or raw[: len(_HEADER)] != _HEADER:
        return LoadResult.NO_IMAGE, None, None
    if crc16(raw[:-2]) != int.from_bytes(raw[-2:], "little"):
        return LoadResult.BAD_CRC, None, None
    offset = len(_HEADER)
    try:
        config = SetConfig.unpack(raw[offset : offset + CONFIG_SIZE])
    except ValueError:
        return LoadResult.INVALID, None, None
    if first_out_of_range(config) is not None or first_inconsistent(config) is not None:
        return LoadResult.INVALID, None, None
    offset += CONFIG_SIZE
    gains: list[Gains] = []
    for wheel in range(WHEEL_COUNT):
        pid = SetPid.unpack(raw[offset : offset + SetPid.PAYLOAD_SIZE])
        offset += SetPid.PAYLOAD_SIZE
        if pid.wheel != wheel or first_out_of_range(pid) is not None:
            return LoadResult.INVALID, None, None
        gains.append(Gains(pid.kp, pid.ki, pid.kd, pid.kf, pid.ks))
    return LoadResult.OK, config, gains
