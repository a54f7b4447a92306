"""The firmware's side of the link: frame decoder, seq accounting, counters and the tx seq."""

from __future__ import annotations

from dataclasses import dataclass

from protocol.codec.message import Message
from protocol.framing import Frame, FrameDecoder, encode_frame


@dataclass(slots=True)
class LinkCounters:
    """What LINK_STATS reports: the decoder's counters plus the firmware's own."""

    frames_ok: int = 0
    crc_errors: int = 0
    cobs_errors: int = 0
    length_errors: int = 0
    unknown_ids: int = 0
    value_errors: int = 0
    seq_gaps: int = 0
    bytes_discarded: int = 0
    rx_overruns: int = 0
    duplicates: int = 0
    frames_sent: int = 0


class FirmwareLink:
    def __init__(self) -> None:
        self.decoder = FrameDecoder()
        self.rx_overruns = 0
        self.seq_gaps = 0
        self.duplicates = 0
        self.frames_sent = 0
        self._tx_seq = 0
        self._last_seq: int | None = None

    def feed(self, data: bytes) -> list[Frame]:
        """Valid frames in `data`; rejected ones are only counted (docs/control.md 1.1)."""
        return [event for event in self.decoder.feed(data) if isinstance(event, Frame)]

    def account_seq(self, seq: int) -> None:
        """docs/control.md 1.2.1: a retry (same seq) counts nothing, a jump counts the gap."""
        last = self._last_seq
        if last is not None and seq != last:
            self.seq_gaps += (seq - (last + 1)) % 256
        self._last_seq = seq

    def restart_seq_accounting(self) -> None:
        """After an accepted HELLO the next frame sets last_seq without counting a gap."""
        self._last_seq = None

    def encode(self, msg: Message) -> bytes:
        wire = encode_frame(msg, self._tx_seq)
        self._tx_seq = (self._tx_seq + 1) & 0xFF
        self.frames_sent += 1
        return wire

    def counters(self) -> LinkCounters:
        s = self.decoder.stats
        return LinkCounters(
            frames_ok=s.frames_ok,
            crc_errors=s.crc_errors,
            cobs_errors=s.cobs_errors,
            length_errors=s.length_errors,
            unknown_ids=s.unknown_ids,
            value_errors=s.value_errors,
            seq_gaps=self.seq_gaps,
            bytes_discarded=s.bytes_discarded,
            rx_overruns=self.rx_overruns,
            duplicates=self.duplicates,
            frames_sent=self.frames_sent,
        )
