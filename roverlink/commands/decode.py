"""`roverlink decode`: frames given in hex, decoded and shown field by field."""

from __future__ import annotations

import argparse
import sys

from protocol.codec.cobs import cobs_decode
from protocol.framing import FrameDecoder
from protocol.generated import oracle
from roverlink.commands.roundtrip import describe


def cmd_decode(args: argparse.Namespace) -> int:
    """Decode hex frames given as arguments (or on stdin), field by field."""
    text = " ".join(args.hex) if args.hex else sys.stdin.read()
    try:
        data = bytes.fromhex(text.replace(":", " "))
    except ValueError as exc:
        print(f"error: not hex: {exc}", file=sys.stderr)
        return 2
    if not data.endswith(b"\x00"):
        data += b"\x00"
    for event in FrameDecoder().feed(data):
        print(describe(event))
    for chunk in data.split(b"\x00"):
        body = cobs_decode(chunk) if chunk else None
        if body is None or len(body) < 4 or body[0] not in oracle.PAYLOADS:
            continue
        print(f"\n{oracle.NAMES[body[0]]} seq={body[1]} crc=0x{body[-2] | body[-1] << 8:04X}")
        try:
            print(oracle.PAYLOADS[body[0]].parse(body[2:-2]))
        except Exception as exc:  # construct raises many types on malformed input
            print(f"  (payload does not parse: {exc})")
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser("decode", help=cmd_decode.__doc__)
    p.add_argument("hex", nargs="*", help="frame bytes in hex (default: read stdin)")
    p.set_defaults(func=cmd_decode)
