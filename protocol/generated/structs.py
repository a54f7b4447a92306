# DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
# spec hash: 0xBDF31659
"""Field sets the spec declares as structs (see [[field_sets]] in the spec)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

DECODER_COUNTERS: Final[tuple[str, ...]] = (
    "frames_ok",
    "crc_errors",
    "cobs_errors",
    "length_errors",
    "unknown_ids",
    "value_errors",
    "bytes_discarded",
)
"""Field names of DecoderCounters, in wire order."""


@dataclass(slots=True)
class DecoderCounters:
    """What a frame decoder counts (the firmware's and the SDK's alike): every received byte ends up in a valid frame or in bytes_discarded. Kept (and counted) in place."""

    frames_ok: int = 0
    """Valid frames received."""
    crc_errors: int = 0
    """Frames with a bad CRC."""
    cobs_errors: int = 0
    """Chunks that were not valid COBS or were over-long."""
    length_errors: int = 0
    """Frames whose length does not fit their msg_id."""
    unknown_ids: int = 0
    """Frames with an unknown msg_id."""
    value_errors: int = 0
    """Frames with a good CRC but a value the spec does not allow (e.g. an unknown enum value)."""
    bytes_discarded: int = 0
    """Received bytes that were not part of a valid frame."""


@dataclass(frozen=True, slots=True)
class DecoderCountersSnapshot:
    """What a frame decoder counts (the firmware's and the SDK's alike): every received byte ends up in a valid frame or in bytes_discarded. The values of a DecoderCounters at one moment."""

    frames_ok: int = 0
    """Valid frames received."""
    crc_errors: int = 0
    """Frames with a bad CRC."""
    cobs_errors: int = 0
    """Chunks that were not valid COBS or were over-long."""
    length_errors: int = 0
    """Frames whose length does not fit their msg_id."""
    unknown_ids: int = 0
    """Frames with an unknown msg_id."""
    value_errors: int = 0
    """Frames with a good CRC but a value the spec does not allow (e.g. an unknown enum value)."""
    bytes_discarded: int = 0
    """Received bytes that were not part of a valid frame."""

LINK_COUNTERS: Final[tuple[str, ...]] = (
    "seq_gaps",
    "duplicates",
    "frames_sent",
    "rx_overruns",
)
"""Field names of LinkCounters, in wire order."""


@dataclass(slots=True)
class LinkCounters:
    """What the firmware's link layer counts besides its decoder. Kept (and counted) in place."""

    seq_gaps: int = 0
    """Host frames missing according to seq."""
    duplicates: int = 0
    """Reliable requests received again (answered, not re-applied)."""
    frames_sent: int = 0
    """Frames sent."""
    rx_overruns: int = 0
    """Bytes lost because the receive buffer was full."""


@dataclass(frozen=True, slots=True)
class LinkCountersSnapshot:
    """What the firmware's link layer counts besides its decoder. The values of a LinkCounters at one moment."""

    seq_gaps: int = 0
    """Host frames missing according to seq."""
    duplicates: int = 0
    """Reliable requests received again (answered, not re-applied)."""
    frames_sent: int = 0
    """Frames sent."""
    rx_overruns: int = 0
    """Bytes lost because the receive buffer was full."""


__all__ = [
    "DECODER_COUNTERS",
    "DecoderCounters",
    "DecoderCountersSnapshot",
    "LINK_COUNTERS",
    "LinkCounters",
    "LinkCountersSnapshot",
]
