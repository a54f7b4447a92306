"""Field values of a message, normalised so the fast codec and the construct oracle compare exactly."""

from __future__ import annotations

from typing import Any

from protocol.codec.message import FieldInfo, Message
from protocol.generated import oracle


def _exact(info: FieldInfo, value: Any) -> Any:
    """One element as a plain, exactly comparable value (floats by bit pattern: -0.0 != 0.0)."""
    if info.kind == "float":
        return float(value).hex()
    return int(value)


def codec_values(msg: Message) -> dict[str, Any]:
    """Field values of a message from the fast codec, normalised: arrays as lists, enums as ints."""
    out: dict[str, Any] = {}
    for info in msg.FIELDS:
        value = getattr(msg, info.name)
        if info.kind in ("str", "bytes"):
            out[info.name] = value
        elif info.count is not None:
            out[info.name] = [_exact(info, v) for v in value]
        else:
            out[info.name] = _exact(info, value)
    return out


def oracle_values(cls: type[Message], payload: bytes) -> dict[str, Any]:
    """Field values of a payload parsed by the construct oracle, normalised like codec_values."""
    parsed = oracle.PAYLOADS[cls.MSG_ID].parse(payload)
    out: dict[str, Any] = {}
    for info in cls.FIELDS:
        value = parsed[info.name]
        if info.kind == "str":
            out[info.name] = bytes(value).decode("ascii")  # GreedyBytes tail
        elif info.kind == "bytes":
            out[info.name] = bytes(value)
        elif info.count is not None:
            out[info.name] = [_exact(info, v) for v in value]
        else:
            out[info.name] = _exact(info, value)
    # Rebuilding gives a payload as long only if the oracle consumed all of it. (Not the same bytes:
    # a signalling-NaN f32 comes back quiet, as Python floats are doubles.)
    assert len(oracle.PAYLOADS[cls.MSG_ID].build(parsed)) == len(payload)
    return out
