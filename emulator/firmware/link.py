"""The firmware's side of the link: frame decoder, seq accounting, counters and the tx seq."""

from __future__ import annotations

from dataclasses import asdict, dataclass

from emulator.firmware.config import first_refused_field
from protocol.codec.cobs import cobs_decode
from protocol.codec.message import Delivery, Direction, Message
from protocol.framing import BadFrame, Frame, FrameDecoder, FrameErrorKind, encode_frame
from protocol.generated.messages import BY_ID, LinkStats
from protocol.generated.structs import DECODER_COUNTERS, LinkCounters

_U32 = 0xFFFFFFFF


@dataclass(frozen=True, slots=True)
class BadValue:
    """A reliable request in an intact frame, holding a value its type does not define (an enum
    value outside the enum): the firmware answers it with NACK(OUT_OF_RANGE, detail = field)."""

    request: type[Message]
    seq: int
    field: int
    """Index of the first field outside its range or undefined (the firmware's check_ranges())."""


class FirmwareLink:
    """The decoder keeps the spec's decoder counters, `counts` the link's own (LinkCounters), as
    the C++ link does; LINK_STATS carries the two sets in that order."""

    def __init__(self) -> None:
        self.decoder = FrameDecoder()
        self.counts = LinkCounters()
        self._tx_seq = 0
        self._last_seq: int | None = None

    def feed(self, data: bytes) -> list[Frame | BadValue]:
        """Valid frames in `data`, and reliable requests whose values the decoder refused (1.4);
        rejected frames are only counted (docs/control.md 1.1)."""
        out: list[Frame | BadValue] = []
        for event in self.decoder.feed(data):
            if isinstance(event, Frame):
                out.append(event)
            elif event.kind is FrameErrorKind.VALUE:
                bad = self._bad_value(event)
                if bad is not None:
                    out.append(bad)
        return out

    def _bad_value(self, bad: BadFrame) -> BadValue | None:
        """A reliable request's values are the firmware's to check, not the decoder's (the C++
        dispatcher leaves them to check_ranges()): counted as a good frame, answered by the caller."""
        cls = BY_ID.get(bad.msg_id) if bad.msg_id is not None else None
        if cls is None or cls.DIRECTION is not Direction.HOST_TO_MCU or cls.DELIVERY is not Delivery.RELIABLE:
            return None
        body = cobs_decode(bad.data)
        field = first_refused_field(cls, body[2:-2]) if body is not None else None
        if body is None or field is None:  # pragma: no cover - the decoder refused a value, so some field is undefined
            return None
        stats = self.decoder.stats
        stats.value_errors -= 1
        stats.bytes_discarded -= len(bad.data)
        stats.frames_ok += 1
        return BadValue(cls, body[1], field)

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
