"""The line budget of docs/budgets.md: 100 Hz setpoints and 100 Hz FEEDBACK at 115200 baud use at
most 40 % of either direction of the serial line.

Computed from the frames' sizes, which the spec fixes: the setpoints and FEEDBACK have fixed
payloads, and a frame is its payload plus 6 bytes (COBS code, msg_id, seq, CRC-16, delimiter: COBS
adds exactly one byte to a body shorter than 254 bytes). 8N1 framing puts 10 bits on the line per
byte. `benchmarks/firmware.py` prints the shares per example and fails when one is over budget.
"""

from __future__ import annotations

from dataclasses import dataclass

from host_sdk import messages
from protocol.codec.message import Message

BAUD = 115_200
BITS_PER_BYTE = 10  # start, 8 data bits, stop
RATE_HZ = 100
LINE_SHARE_BUDGET = 0.40
FRAME_OVERHEAD = 6


@dataclass(frozen=True)
class LineUse:
    setpoint: str
    setpoint_frame_bytes: int
    feedback_frame_bytes: int
    host_to_mcu: float
    """Share of the host-to-MCU direction taken by RATE_HZ setpoints."""
    mcu_to_host: float
    """Share of the MCU-to-host direction taken by RATE_HZ FEEDBACK frames."""

    @property
    def full_duplex(self) -> float:
        """Share of both directions together."""
        return (self.host_to_mcu + self.mcu_to_host) / 2


def frame_bytes(cls: type[Message]) -> int:
    """Bytes on the wire of every frame of a message with a fixed payload."""
    if cls.PAYLOAD_SIZE != cls.PAYLOAD_MAX:
        raise ValueError(f"{cls.NAME} has a variable payload: no single frame size")
    return cls.PAYLOAD_SIZE + FRAME_OVERHEAD


def share(frame: int, rate_hz: int = RATE_HZ, baud: int = BAUD) -> float:
    """Share of one direction of the line that `rate_hz` frames of `frame` bytes take."""
    return frame * BITS_PER_BYTE * rate_hz / baud


def line_use(setpoint: type[Message], baud: int = BAUD) -> LineUse:
    sp = frame_bytes(setpoint)
    fb = frame_bytes(messages.Feedback)
    return LineUse(setpoint.NAME, sp, fb, share(sp, baud=baud), share(fb, baud=baud))


def report(u: LineUse, baud: int = BAUD) -> str:
    return (
        f"line at {RATE_HZ} Hz both ways, {baud} baud: {u.setpoint} {u.setpoint_frame_bytes} B -> "
        f"{u.host_to_mcu:.1%} of host-to-MCU, FEEDBACK {u.feedback_frame_bytes} B -> {u.mcu_to_host:.1%} of "
        f"MCU-to-host ({u.full_duplex:.1%} of the full-duplex line; budget {LINE_SHARE_BUDGET:.0%} of either)"
    )


def problems(u: LineUse) -> list[str]:
    return [
        f"{name} at {RATE_HZ} Hz uses {value:.1%} of the {direction} direction > {LINE_SHARE_BUDGET:.0%}"
        for name, value, direction in (
            (u.setpoint, u.host_to_mcu, "host-to-MCU"),
            ("FEEDBACK", u.mcu_to_host, "MCU-to-host"),
        )
        if value > LINE_SHARE_BUDGET
    ]
