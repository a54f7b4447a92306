"""The firmware's side of the link: frame decoder, seq accounting, counters and the tx seq."""

from __future__ import annotations

from dataclasses import asdict

from protocol.codec.message import Message
from protocol.framing import Frame, FrameDecoder, encode_frame
from protocol.generated.messages import LinkStats
from protocol.generated.structs import DECODER_COUNTERS, LinkCounters

_U32 = 0xFFFFFFFF


class FirmwareLink:
    """The decoder keeps the spec's decoder counters, `counts` the link's own (LinkCounters), as
    the C++ link does; LINK_STATS carries the two sets in that order."""

    def __init__(self) -> None:
        self.decoder = FrameDecoder()
        self.counts = LinkCounters()
        self._tx_seq = 0
        self._last_seq: int | None = None

    def feed(self, data: bytes) -> list[Frame]:
        """Valid frames in `data`; rejected ones are only counted (docs/control.md 1.1)."""
        return [event for event in self.decoder.feed(data) if isinstance(event, Frame)]

    def account_seq(self, seq: int) -> None:
        """docs/control.md 1.2.1: a retry (same seq) counts nothing, a jump counts the gap."""
        last = self._last_seq
        if last is not None and seq != last:
            self.counts.seq_gaps += (seq - (last + 1)) % 256
        self._last_seq = seq

    def restart_seq_accounting(self) -> None:
        """After an accepted HELLO the next frame sets last_seq without counting a gap."""
        self._last_seq = None

    def encode(self, msg: Message) -> bytes:
        wire = encode_frame(msg, self._tx_seq)
        self._tx_seq = (self._tx_seq + 1) & 0xFF
        self.counts.frames_sent += 1
        return wire

    def stats(self, req_seq: int = 0) -> LinkStats:
        """LINK_STATS as the firmware would answer now (u32 counters wrap as on the MCU)."""
        decoder = self.decoder.stats
        values = {name: getattr(decoder, name) & _U32 for name in DECODER_COUNTERS}
        values.update({name: value & _U32 for name, value in asdict(self.counts).items()})
        return LinkStats(req_seq=req_seq, **values)
