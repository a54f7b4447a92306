"""`roverlink spec`: the protocol version, spec hash and every message."""

from __future__ import annotations

import argparse

from protocol.generated import messages
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH


def cmd_spec(_args: argparse.Namespace) -> int:
    print(f"protocol version {PROTOCOL_VERSION}, spec hash 0x{SPEC_HASH:08X}")
    for cls in messages.ALL_MESSAGES:
        size = (
            f"{cls.PAYLOAD_SIZE}" if cls.PAYLOAD_SIZE == cls.PAYLOAD_MAX else f"{cls.PAYLOAD_SIZE}..{cls.PAYLOAD_MAX}"
        )
        print(f"  0x{cls.MSG_ID:02X} {cls.NAME:<17} {cls.DIRECTION.value:<12} {cls.DELIVERY.value:<10} {size} B")
    return 0


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    sub.add_parser(
        "spec",
        help="print the protocol version, spec hash and messages",
        description="The protocol version, the spec hash and every message: id, direction, delivery, payload size.",
    ).set_defaults(func=cmd_spec)
