"""The frame codec bound to RoverLink's messages: `encode_frame(msg, seq)` and `FrameDecoder()`.

>>> from protocol.framing import FrameDecoder, encode_frame
>>> from protocol.generated.messages import SetWheelSpeeds
>>> wire = encode_frame(SetWheelSpeeds(left_mm_s=120, right_mm_s=-80), seq=7)
>>> [event] = FrameDecoder().feed(wire)
>>> event.message, event.seq
(SetWheelSpeeds(left_mm_s=120, right_mm_s=-80), 7)

protocol.codec knows frames and the message base class; protocol.generated knows the messages;
this module joins the two, so neither of them imports the other's side.
"""

from __future__ import annotations

from protocol.codec import frames as _frames
from protocol.codec.frames import BadFrame, DecoderStats, Frame, FrameErrorKind, MessageTable, encode_frame
from protocol.generated.constants import MAX_FRAME
from protocol.generated.messages import ALL_MESSAGES

__all__ = ["MESSAGES", "BadFrame", "DecoderStats", "Frame", "FrameDecoder", "FrameErrorKind", "encode_frame"]

MESSAGES = MessageTable(ALL_MESSAGES, MAX_FRAME)
"""Every message of the spec, by msg_id."""


class FrameDecoder(_frames.FrameDecoder):
    """Turns a byte stream, in chunks of any size, into Frame and BadFrame events, in order.

    Never raises on input: bad data is counted in `stats` and reported as BadFrame. Memory is
    bounded: a run longer than any frame without a delimiter is discarded (one COBS error) and
    the decoder resynchronises at the next 0x00. Knows every message of the spec unless given
    another `table`.
    """

    __slots__ = ()

    def __init__(self, table: MessageTable = MESSAGES) -> None:
        super().__init__(table)
