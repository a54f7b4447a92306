"""`roverlink decode`: frames given in hex, decoded and shown field by field.

    $ roverlink decode 09 20 05 2c 01 38 ff 8c 0e 00
    frame 1: SET_WHEEL_SPEEDS (0x20) seq 5, CRC ok
      left_mm_s   300 mm/s
      right_mm_s  -200 mm/s

Exit status: 0 when every frame is valid, 1 when any is not (each bad one says why: CRC, COBS,
length, unknown id, a value outside the spec), 2 when the input is not hex.
"""

from __future__ import annotations

import argparse
import enum
import sys

from protocol.codec.cobs import cobs_decode
from protocol.codec.crc import frame_crc
from protocol.codec.message import Message
from protocol.framing import MESSAGES, BadFrame, Frame, FrameDecoder, FrameErrorKind
from roverlink import say


def cmd_decode(args: argparse.Namespace) -> int:
    """Decode RoverLink frames given in hex (arguments or stdin) and show them field by field."""
    text = " ".join(args.hex) if args.hex else sys.stdin.read()
    cleaned = text.replace(":", " ").replace(",", " ")
    try:
        data = bytes.fromhex(cleaned)
    except ValueError:
        bad = next((word for word in cleaned.split() if not _is_hex(word)), cleaned.strip()[:20])
        say.error(f"not hex: {bad!r} (give bytes as hex digit pairs, e.g. 01 A2 ff, or 01a2ff)")
        return 2
    if not data:
        say.error("no bytes given")
        return 2
    if not data.endswith(b"\x00"):
        data += b"\x00"  # the last frame's delimiter may be left out
    bad = 0
    for n, event in enumerate(FrameDecoder().feed(data), 1):
        if isinstance(event, Frame):
            print("\n".join(describe_frame(n, event)))
        else:
            bad += 1
            print("\n".join(describe_bad(n, event)))
    if bad:
        print(f"{bad} bad frame{'s' if bad > 1 else ''}", file=sys.stderr)
    return 1 if bad else 0


def describe_frame(n: int, frame: Frame) -> list[str]:
    """A valid frame: its message, seq and each field with its unit."""
    msg = frame.message
    lines = [f"frame {n}: {msg.NAME} (0x{msg.MSG_ID:02X}) seq {frame.seq}, CRC ok"]
    lines += fields(msg)
    return lines


def fields(msg: Message) -> list[str]:
    """`name  value unit` per field, enums and flags by name."""
    width = max((len(f.name) for f in msg.FIELDS), default=0)
    out = []
    for info in msg.FIELDS:
        value = getattr(msg, info.name)
        shown = _show(value)
        unit = f" {info.unit}" if info.unit else ""
        out.append(f"  {info.name:<{width}}  {shown}{unit}")
    return out


def _show(value: object) -> str:
    if isinstance(value, enum.Flag):
        names = [m.name for m in type(value) if m.value and m in value and m.name]
        return " | ".join(names) if names else "0"
    if isinstance(value, enum.Enum):
        return str(value.name)
    if isinstance(value, (tuple, list)):
        return "(" + ", ".join(_show(v) for v in value) + ")"
    if isinstance(value, float):
        return f"{value:g}"
    return repr(value) if isinstance(value, (str, bytes)) else str(value)


def describe_bad(n: int, bad: BadFrame) -> list[str]:
    """A frame that is not valid: the kind of error, and for a CRC error both CRCs."""
    where = f" (msg_id 0x{bad.msg_id:02X})" if bad.msg_id is not None else ""
    lines = [f"frame {n}: BAD {bad.kind.value}{where}: {bad.detail}"]
    if bad.kind is FrameErrorKind.CRC and bad.msg_id is not None:
        body = cobs_decode(bad.data)
        cls = MESSAGES.by_id.get(bad.msg_id)
        if body is not None and cls is not None:
            sent = body[-2] | body[-1] << 8
            lines.append(f"  CRC 0x{sent:04X} on the wire, 0x{frame_crc(body[:-2], cls.CRC_EXTRA):04X} computed")
    lines.append(f"  bytes: {bad.data.hex(' ')}")
    return lines


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("decode", help=cmd_decode.__doc__, description=__doc__, formatter_class=_Raw)
    p.add_argument("hex", nargs="*", help="frame bytes in hex, delimiters included (default: read stdin)")
    p.set_defaults(func=cmd_decode)


class _Raw(argparse.RawDescriptionHelpFormatter):
    pass


def _is_hex(word: str) -> bool:
    """Whole bytes of hex digits."""
    return len(word) % 2 == 0 and all(c in "0123456789abcdefABCDEF" for c in word)
