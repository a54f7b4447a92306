"""The session's frames: numbered and counted on the way out, decoded and their numbering checked
on the way in."""

from __future__ import annotations

from host_sdk.framing import FrameDecoder, encode_frame
from host_sdk.session.counters import HostCounters
from protocol.codec.message import Message


class Wire:
    """Everything the session sends goes through `send` and waits in a buffer until `take`."""

    __slots__ = ("_decoder", "_last_rx", "_last_tx", "_n", "_out", "_rx_seq", "_tx_seq")

    def __init__(self, counters: HostCounters) -> None:
        self._n = counters
        self._decoder = FrameDecoder()
        self._out: list[bytes] = []
        self._tx_seq = 0
        self._rx_seq: int | None = None
        self._last_tx = 0.0
        self._last_rx: float | None = None

    @property
    def decoder(self) -> FrameDecoder:
        """The decoder of the board's bytes (its stats count every byte received)."""
        return self._decoder

    @property
    def next_seq(self) -> int:
        """The seq the next new frame gets."""
        return self._tx_seq

    @property
    def last_tx(self) -> float:
        """When a frame was last sent."""
        return self._last_tx

    @property
    def last_rx(self) -> float | None:
        """When a frame last arrived (None before the first)."""
        return self._last_rx

    def send(self, msg: Message, now: float, seq: int | None = None) -> int:
        """Queue `msg` for the board, with the next seq or (a retry) `seq`; returns the seq."""
        if seq is None:
            seq = self._tx_seq
            self._tx_seq = (self._tx_seq + 1) & 0xFF
        wire = encode_frame(msg, seq)
        self._out.append(wire)
        self._n.frames_sent += 1
        self._n.bytes_sent += len(wire)
        self._last_tx = now
        return seq

    def take(self) -> bytes:
        """Bytes to write to the board, in order (taking them empties the buffer)."""
        if not self._out:
            return b""
        data = b"".join(self._out)
        self._out.clear()
        return data

    def received(self, seq: int, now: float) -> None:
        """A board frame numbered `seq` arrived at `now`: count the frames missing before it."""
        self._last_rx = now
        last = self._rx_seq
        if last is not None:
            self._n.seq_gaps += (seq - last - 1) % 256
        self._rx_seq = seq

    def renumbered(self) -> None:
        """A new boot numbers its frames from 0 again: no gap to count before the next one."""
        self._rx_seq = None
