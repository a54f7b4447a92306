"""The reliable requests that need a session (docs/control.md 2), one function each.

Each applies its request to the firmware and returns the answer (ACK, NACK or the reply). The
firmware sends it and keeps it for the duplicate rule, after the check every one of them shares:
outside a session the answer is NACK(NO_SESSION) and nothing is applied (Firmware._on_request).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, Protocol

from emulator.firmware.board import Board
from emulator.firmware.config import (
    IMAGE_ADDR,
    IMAGE_SIZE,
    Gains,
    encode_image,
    first_inconsistent,
    first_out_of_range,
    pid_wheel_ok,
)
from emulator.firmware.link import FirmwareLink
from emulator.firmware.session import Session
from emulator.firmware.statemachine import SessionState
from protocol.codec.message import Message
from protocol.generated.constants import WHEEL_COUNT
from protocol.generated.enums import Capability, NackReason
from protocol.generated.messages import (
    Ack,
    Config,
    GetConfig,
    GetLights,
    GetLinkStats,
    GetPid,
    LightsState,
    Nack,
    Pid,
    ResetOdometry,
    SaveConfig,
    SetConfig,
    SetLights,
    SetPid,
)


class RequestTarget(Protocol):
    """What the requests read and change in one boot of the firmware. Firmware (core.py) is one;
    it imports this module, so this module names the part it needs rather than importing it."""

    board: Board
    caps: Capability
    session: Session
    link: FirmwareLink
    config: SetConfig
    gains: list[Gains]
    counts: list[int]
    config_defaults: bool
    lights_setting: SetLights
    lit: int

    def set_gains(self, wheels: Iterable[int], gains: Gains) -> None: ...

    def set_config(self, config: SetConfig) -> None: ...


def ack(msg: Message | type[Message], seq: int) -> Ack:
    return Ack(req_id=msg.MSG_ID, req_seq=seq)


def nack(msg: Message | type[Message], seq: int, reason: NackReason, detail: int = 0) -> Nack:
    return Nack(req_id=msg.MSG_ID, req_seq=seq, reason=reason, detail=detail & 0xFF)


def set_pid(fw: RequestTarget, msg: SetPid, seq: int) -> Message:
    if not pid_wheel_ok(msg.wheel):
        return nack(msg, seq, NackReason.OUT_OF_RANGE, 0)
    bad = first_out_of_range(msg)
    if bad is not None:
        return nack(msg, seq, NackReason.OUT_OF_RANGE, bad)
    fw.set_gains(range(WHEEL_COUNT) if msg.wheel >= WHEEL_COUNT else (msg.wheel,), Gains.of(msg))
    return ack(msg, seq)


def get_pid(fw: RequestTarget, msg: GetPid, seq: int) -> Message:
    if not 0 <= msg.wheel < WHEEL_COUNT:
        return nack(msg, seq, NackReason.OUT_OF_RANGE, 0)
    g = fw.gains[msg.wheel]
    return Pid(req_seq=seq, wheel=msg.wheel, kp=g.kp, ki=g.ki, kd=g.kd, kf=g.kf, ks=g.ks)


def set_config(fw: RequestTarget, msg: SetConfig, seq: int) -> Message:
    bad = first_out_of_range(msg)
    if bad is not None:
        return nack(msg, seq, NackReason.OUT_OF_RANGE, bad)
    bad = first_inconsistent(msg)
    if bad is not None:
        return nack(msg, seq, NackReason.INVALID_CONFIG, bad)
    fw.set_config(msg)
    return ack(msg, seq)


def get_config(fw: RequestTarget, msg: GetConfig, seq: int) -> Message:
    return Config(req_seq=seq, **fw.config.fields())


def save_config(fw: RequestTarget, msg: SaveConfig, seq: int) -> Message:
    if not fw.caps & Capability.EEPROM:
        return nack(msg, seq, NackReason.UNSUPPORTED)
    if fw.session.state is SessionState.ARMED:
        return nack(msg, seq, NackReason.ARMED)
    image = encode_image(fw.config, fw.gains)
    written = fw.board.eeprom_write(IMAGE_ADDR, image)
    if not written or fw.board.eeprom_read(IMAGE_ADDR, IMAGE_SIZE) != image:
        return nack(msg, seq, NackReason.EEPROM_ERROR)
    fw.config_defaults = False
    return ack(msg, seq)


def reset_odometry(fw: RequestTarget, msg: ResetOdometry, seq: int) -> Message:
    fw.board.zero_encoders()
    fw.counts = [0] * WHEEL_COUNT  # the measurement baseline too: no speed spike
    return ack(msg, seq)


def get_link_stats(fw: RequestTarget, msg: GetLinkStats, seq: int) -> Message:
    return fw.link.stats(seq)


def set_lights(fw: RequestTarget, msg: SetLights, seq: int) -> Message:
    # Ranges before the capability, as the bad-value rule (1.4) answers an undefined mode anyway.
    bad = first_out_of_range(msg)
    if bad is not None:
        return nack(msg, seq, NackReason.OUT_OF_RANGE, bad)
    if not fw.caps & Capability.TURN_SIGNALS:
        return nack(msg, seq, NackReason.UNSUPPORTED)
    fw.lights_setting = msg  # the next tick shows it
    return ack(msg, seq)


def get_lights(fw: RequestTarget, msg: GetLights, seq: int) -> Message:
    if not fw.caps & Capability.TURN_SIGNALS:
        return nack(msg, seq, NackReason.UNSUPPORTED)
    return LightsState(req_seq=seq, **fw.lights_setting.fields(), lit=fw.lit)


@dataclass(frozen=True)
class Request:
    apply: Callable[[RequestTarget, Any, int], Message]
    fresh: bool = False
    """A GET_*: a repeat is answered with the current values (reading changes nothing)."""


REQUESTS: dict[type[Message], Request] = {
    SetPid: Request(set_pid),
    GetPid: Request(get_pid, fresh=True),
    SetConfig: Request(set_config),
    GetConfig: Request(get_config, fresh=True),
    SaveConfig: Request(save_config),
    ResetOdometry: Request(reset_odometry),
    GetLinkStats: Request(get_link_stats, fresh=True),
    SetLights: Request(set_lights),
    GetLights: Request(get_lights, fresh=True),
}
"""Every reliable request that needs a session, by message class."""
