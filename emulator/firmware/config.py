"""Configuration and PID gains: validation, and their EEPROM record (version byte + CRC-16).

Record layout at address 0 (75 bytes):
    0       version (CONFIG_RECORD_VERSION)
    1..40   SET_CONFIG payload (the wire layout, little-endian)
    41..72  PID gains of wheel 0 then wheel 1: kp, ki, kd, kf as f32 little-endian
    73..74  CRC-16/CCITT-FALSE of bytes 0..72, little-endian
The boot counter (u32, little-endian) lives in the last 4 bytes of the EEPROM.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass

from host_sdk._generated.constants import PID_ALL_WHEELS, WHEEL_COUNT
from host_sdk.codec.crc import crc16
from host_sdk.codec.message import FieldInfo, Message
from host_sdk.messages import SetConfig, SetPid

CONFIG_RECORD_VERSION = 1
_GAINS = struct.Struct("<ffff")
CONFIG_SIZE = SetConfig.PAYLOAD_SIZE
RECORD_SIZE = 1 + CONFIG_SIZE + WHEEL_COUNT * _GAINS.size + 2
_F32 = struct.Struct("<f")


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

    @classmethod
    def of(cls, pid: SetPid) -> Gains:
        return cls(f32(pid.kp), f32(pid.ki), f32(pid.kd), f32(pid.kf))


def first_out_of_range(msg: Message) -> int | None:
    """Index of the first field outside its spec range (the firmware's generated check_ranges),
    or None. NaN and infinity are out of range."""
    for index, info in enumerate(msg.FIELDS):
        if not _in_range(info, getattr(msg, info.name)):
            return index
    return None


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


def encode_record(config: SetConfig, gains: list[Gains]) -> bytes:
    body = bytes((CONFIG_RECORD_VERSION,)) + config.pack()
    for g in gains:
        body += _GAINS.pack(g.kp, g.ki, g.kd, g.kf)
    return body + crc16(body).to_bytes(2, "little")


def decode_record(raw: bytes) -> tuple[SetConfig, list[Gains]] | None:
    """Config and gains from an EEPROM record, or None when the version, CRC or values are bad."""
    if len(raw) != RECORD_SIZE or raw[0] != CONFIG_RECORD_VERSION:
        return None
    if crc16(raw[:-2]) != int.from_bytes(raw[-2:], "little"):
        return None
    try:
        config = SetConfig.unpack(raw[1 : 1 + CONFIG_SIZE])
    except ValueError:
        return None
    if first_out_of_range(config) is not None or first_inconsistent(config) is not None:
        return None
    gains: list[Gains] = []
    offset = 1 + CONFIG_SIZE
    for _ in range(WHEEL_COUNT):
        kp, ki, kd, kf = _GAINS.unpack_from(raw, offset)
        offset += _GAINS.size
        g = Gains(kp, ki, kd, kf)
        if first_out_of_range(SetPid(0, g.kp, g.ki, g.kd, g.kf)) is not None:
            return None
        gains.append(g)
    return config, gains
