"""Frame-level codec: `encode_frame(msg, seq)` and the streaming `FrameDecoder` (from protocol.framing).

>>> from host_sdk import messages
>>> from host_sdk.framing import FrameDecoder, encode_frame
>>> wire = encode_frame(messages.SetWheelSpeeds(left_mm_s=120, right_mm_s=-80), seq=7)
>>> [event] = FrameDecoder().feed(wire)
>>> event.message, event.seq
(SetWheelSpeeds(left_mm_s=120, right_mm_s=-80), 7)
"""

from protocol.framing import BadFrame, DecoderStats, Frame, FrameDecoder, FrameErrorKind, encode_frame

__all__ = ["BadFrame", "DecoderStats", "Frame", "FrameDecoder", "FrameErrorKind", "encode_frame"]
