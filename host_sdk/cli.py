"""The `roverlink` command line."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from emulator import cli as emulator_cli
from host_sdk import cli_robot, enums, firmware, messages
from host_sdk._generated import oracle
from host_sdk._generated.constants import PROTOCOL_VERSION, SPEC_HASH
from host_sdk.codec.cobs import cobs_decode
from host_sdk.codec.message import Message
from host_sdk.framing import BadFrame, Frame, FrameDecoder, encode_frame


def _describe(event: Frame | BadFrame) -> str:
    if isinstance(event, Frame):
        return f"ok    seq={event.seq:<3} {event.message}"
    where = f" msg_id=0x{event.msg_id:02X}" if event.msg_id is not None else ""
    return f"BAD   {event.kind.value}{where}: {event.detail}"


def cmd_roundtrip(_args: argparse.Namespace) -> int:
    """Encode a few messages, corrupt the stream, and show the decoder recovering."""
    sample: list[Message] = [
        messages.Hello(PROTOCOL_VERSION, SPEC_HASH, 250, enums.FeedbackMode.STREAM, 50),
        messages.SetWheelSpeeds(left_mm_s=300, right_mm_s=280),
        messages.Feedback(
            boot_id=0x1D2C3B4A,
            mcu_time_us=1_234_567,
            tick=123,
            ack_seq=1,
            ack_tick=122,
            status=enums.Status.SESSION | enums.Status.ARMED,
            failsafe_reason=enums.FailsafeReason.NONE,
            encoder_counts=(15_600, -15_432),
            wheel_speed_mm_s=(301, 279),
            effort_permille=(412, 398),
            steering_mrad=0,
        ),
        messages.Log(enums.LogLevel.INFO, "config loaded from EEPROM"),
    ]
    frames = [encode_frame(m, seq) for seq, m in enumerate(sample)]
    print(f"RoverLink protocol v{PROTOCOL_VERSION}, spec hash 0x{SPEC_HASH:08X}\n")
    for m, f in zip(sample, frames, strict=True):
        print(f"{m.NAME:<17} {len(f):>2} bytes  {f.hex(' ')}")
    stream = bytearray(b"".join(frames))
    stream[len(frames[0]) + 3] ^= 0x10  # one flipped bit in the second frame
    noisy = b"\x7f\xfe bootloader noise \x00" + bytes(stream)
    print("\nThe same stream after bootloader noise and one flipped bit, fed 5 bytes at a time:")
    decoder = FrameDecoder()
    for i in range(0, len(noisy), 5):
        for event in decoder.feed(noisy[i : i + 5]):
            print("  " + _describe(event))
    print("\ndecoder stats:", ", ".join(f"{k}={v}" for k, v in decoder.stats.as_dict().items()))
    ok = decoder.stats.frames_ok == len(frames) - 1
    print("round trip:", "OK (the corrupted frame was dropped, every other frame arrived)" if ok else "FAILED")
    return 0 if ok else 1


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
        print(_describe(event))
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


def cmd_spec(_args: argparse.Namespace) -> int:
    print(f"protocol version {PROTOCOL_VERSION}, spec hash 0x{SPEC_HASH:08X}")
    for cls in messages.ALL_MESSAGES:
        size = (
            f"{cls.PAYLOAD_SIZE}" if cls.PAYLOAD_SIZE == cls.PAYLOAD_MAX else f"{cls.PAYLOAD_SIZE}..{cls.PAYLOAD_MAX}"
        )
        print(f"  0x{cls.MSG_ID:02X} {cls.NAME:<17} {cls.DIRECTION.value:<12} {cls.DELIVERY.value:<10} {size} B")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="roverlink", description="RoverLink host tools.")
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("roundtrip", help=cmd_roundtrip.__doc__).set_defaults(func=cmd_roundtrip)
    p = sub.add_parser("decode", help=cmd_decode.__doc__)
    p.add_argument("hex", nargs="*", help="frame bytes in hex (default: read stdin)")
    p.set_defaults(func=cmd_decode)
    sub.add_parser("spec", help="print the protocol version, spec hash and messages").set_defaults(func=cmd_spec)
    emulator_cli.add_subparser(sub)
    firmware.add_subparser(sub)
    cli_robot.add_subparsers(sub)
    args = parser.parse_args(argv)
    result: int = args.func(args)
    return result


if __name__ == "__main__":
    sys.exit(main())
