"""The raw-frame host end every firmware suite drives a board with: frames out with a running seq,
frames in, each stamped with the board time it was read at. Deliberately not the SDK's session:
the tests drive the protocol step by step and look at every byte.

`Link` is the byte-level half, over any board (the emulator, the native core, simavr): `send`,
`send_raw`, `receive`. `Host` adds the protocol steps on the emulator's virtual clock (seconds):
`run`, `wait_for`, `request`, `boot`, `hello`, `arm`, `session`, `drive`. The message builders
(`hello`, `raw_frame`) and the rule for which frame answers a request (`answers`) are shared too.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

from emulator import Emulator
from host_sdk import enums, messages
from host_sdk.framing import BadFrame, Frame, FrameDecoder, encode_frame
from protocol.codec.cobs import cobs_encode
from protocol.codec.crc import frame_crc
from protocol.codec.message import Message
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH

M = TypeVar("M", bound=Message)


@dataclass(frozen=True)
class Received:
    time_us: int
    message: Message
    seq: int


def hello(
    mode: enums.FeedbackMode = enums.FeedbackMode.STREAM,
    hz: int = 0,
    watchdog_ms: int = 0,
    spec_hash: int = SPEC_HASH,
) -> messages.Hello:
    """A HELLO of this protocol version (0 for `hz` and `watchdog_ms`: the board's defaults)."""
    return messages.Hello(PROTOCOL_VERSION, spec_hash, watchdog_ms, mode, hz)


def raw_frame(cls: type[Message], payload: bytes, seq: int) -> bytes:
    """A valid frame (good COBS and CRC) around any payload: for values pack() refuses to encode."""
    body = bytes((cls.MSG_ID, seq)) + payload
    return cobs_encode(body + frame_crc(body, cls.CRC_EXTRA).to_bytes(2, "little")) + b"\x00"


def answers(request: Message, seq: int) -> Callable[[Message], bool]:
    """Whether a frame answers `request` sent with `seq`: its ACK or NACK, the IDENTITY of a HELLO,
    or the reply carrying req_seq."""

    def match(m: Message) -> bool:
        if isinstance(m, (messages.Ack, messages.Nack)):
            return m.req_seq == seq and m.req_id == request.MSG_ID
        if isinstance(m, messages.Identity):
            return isinstance(request, messages.Hello) and m.hello_seq == seq and m.reason != enums.IdentityReason.BOOT
        return getattr(m, "req_seq", None) == seq

    return match


class Link:
    """Frames to a board and back: `write` takes host bytes, `read` returns what the board sent,
    `clock` says the board time (us) frames are stamped with."""

    def __init__(
        self, write: Callable[[bytes], None], read: Callable[[], bytes], clock: Callable[[], int], first_seq: int = 0
    ) -> None:
        self._write = write
        self._read = read
        self._clock = clock
        self.seq = first_seq & 0xFF
        self.decoder = FrameDecoder()
        self.received: list[Received] = []
        self.bad: list[BadFrame] = []
        self.raw = bytearray()

    def send(self, msg: Message, seq: int | None = None) -> int:
        """Sends one frame (the next seq unless given); returns its seq."""
        if seq is None:
            seq = self.seq
            self.seq = (self.seq + 1) & 0xFF
        self._write(encode_frame(msg, seq))
        return seq

    def send_raw(self, data: bytes) -> None:
        self._write(data)

    def receive(self) -> list[Received]:
        """Decodes what the board sent since the last call: the new frames (damaged ones go to `bad`)."""
        data = self._read()
        self.raw += data
        new: list[Received] = []
        for event in self.decoder.feed(data):
            if isinstance(event, Frame):
                new.append(Received(self._clock(), event.message, event.seq))
            else:
                self.bad.append(event)
        self.received += new
        return new

    def of(self, kind: type[M]) -> list[M]:
        return [r.message for r in self.received if isinstance(r.message, kind)]

    def timed(self, kind: type[M]) -> list[tuple[int, M]]:
        return [(r.time_us, r.message) for r in self.received if isinstance(r.message, kind)]


class Host(Link):
    """The host end on an emulator, on its virtual clock."""

    def __init__(self, emu: Emulator) -> None:
        super().__init__(emu.host_write, emu.host_read, lambda: emu.now_us)
        self.emu = emu

    def poll(self) -> list[Received]:
        return self.receive()

    def run(self, seconds: float, step_s: float = 0.001) -> list[Received]:
        """Advance `seconds` of virtual time in steps, polling as a host would."""
        end = self.emu.now_us + round(seconds * 1e6)
        new: list[Received] = []
        step = round(step_s * 1e6)
        while self.emu.now_us < end:
            self.emu.advance_to_us(min(end, self.emu.now_us + step))
            new += self.poll()
        return new

    def wait_for(self, kind: type[M], timeout_s: float = 1.0, where: Callable[[M], bool] | None = None) -> M:
        """The first new message of `kind` (matching `where`) within `timeout_s` of virtual time."""
        end = self.emu.now_us + round(timeout_s * 1e6)
        while True:
            for r in self.poll():
                if isinstance(r.message, kind) and (where is None or where(r.message)):
                    return r.message
            if self.emu.now_us >= end:
                raise AssertionError(f"no {kind.__name__} within {timeout_s} s of virtual time")
            self.emu.advance_to_us(min(end, self.emu.now_us + 500))

    # -- protocol steps --------------------------------------------------------------------------
    def boot(self, timeout_s: float = 3.0) -> messages.Identity:
        return self.wait_for(messages.Identity, timeout_s, lambda m: m.reason is enums.IdentityReason.BOOT)

    def hello(
        self,
        mode: enums.FeedbackMode = enums.FeedbackMode.STREAM,
        hz: int = 0,
        watchdog_ms: int = 0,
    ) -> messages.Identity:
        msg = hello(mode, hz, watchdog_ms)
        return self.wait_for(messages.Identity, 0.5, answers(msg, self.send(msg)))

    def request(self, msg: Message, seq: int | None = None, timeout_s: float = 0.5) -> Message:
        """A reliable request and its answer (ACK, NACK or the reply carrying req_seq)."""
        seq = self.send(msg, seq)
        return self.wait_for(Message, timeout_s, answers(msg, seq))

    def arm(self, boot_id: int | None = None) -> Message:
        if boot_id is None:
            fw = self.emu.firmware
            assert fw is not None
            boot_id = fw.boot_id
        return self.request(messages.Arm(boot_id))

    def session(
        self,
        mode: enums.FeedbackMode = enums.FeedbackMode.STREAM,
        hz: int = 0,
        watchdog_ms: int = 0,
        arm: bool = True,
    ) -> messages.Identity:
        """Boot, HELLO and (by default) ARM; returns the HELLO's IDENTITY."""
        boot = self.boot()
        ident = self.hello(mode, hz, watchdog_ms)
        assert ident.boot_id == boot.boot_id
        if arm:
            answer = self.arm(ident.boot_id)
            assert isinstance(answer, messages.Ack), answer
        return ident

    def drive(self, msg: Message, seconds: float, lockstep: bool = False) -> None:
        """Sends the setpoint `msg` every 20 ms for `seconds` (in lockstep: waiting for each FEEDBACK)."""
        for _ in range(round(seconds / 0.02)):
            self.send(msg)
            if lockstep:
                self.wait_for(messages.Feedback, 0.05)
            self.run(0.02)
