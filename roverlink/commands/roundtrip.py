"""`roverlink roundtrip`: the codec at work on a corrupted stream."""

from __future__ import annotations

import argparse

from protocol.codec.message import Message
from protocol.framing import BadFrame, Frame, FrameDecoder, encode_frame
from protocol.generated import enums, messages
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH


def describe(event: Frame | BadFrame) -> str:
    """One line for a decoder event."""
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
            print("  " + describe(event))
    print("\ndecoder stats:", ", ".join(f"{k}={v}" for k, v in decoder.stats.as_dict().items()))
    ok = decoder.stats.frames_ok == len(frames) - 1
    print("round trip:", "OK (the corrupted frame was dropped, every other frame arrived)" if ok else "FAILED")
    return 0 if ok else 1


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    sub.add_parser("roundtrip", help=cmd_roundtrip.__doc__, description=cmd_roundtrip.__doc__).set_defaults(
        func=cmd_roundtrip
    )
