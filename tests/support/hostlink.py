"""A minimal scripted host for the emulator tests: frames out with a seq counter, frames in with
the virtual time they were read at. Deliberately not the SDK's session: the tests drive the
protocol step by step and look at every byte."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

from emulator import Emulator
from host_sdk import enums, messages
from host_sdk.framing import BadFrame, Frame, FrameDecoder, encode_frame
from protocol.codec.message import Message
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH

M = TypeVar("M", bound=Message)


@dataclass(frozen=True)
class Received:
    time_us: int
    message: Message
    seq: int


class Host:
    def __init__(self, emu: Emulator) -> None:
        self.emu = emu
        self.decoder = FrameDecoder()
        self.seq = 0
        self.received: list[Received] = []
        self.bad: list[BadFrame] = []
        self.raw = bytearray()

    # -- sending ---------------------------------------------------------------------------------
    def send(self, msg: Message, seq: int | None = None) -> int:
        if seq is None:
            seq = self.seq
            self.seq = (self.seq + 1) & 0xFF
        self.emu.host_write(encode_frame(msg, seq))
        return seq

    def send_raw(self, data: bytes) -> None:
        self.emu.host_write(data)

    # -- receiving -------------------------------------------------------------------------------
    def poll(self) -> list[Received]:
        data = self.emu.host_read()
        self.raw += data
        new: list[Received] = []
        for event in self.decoder.feed(data):
            if isinstance(event, Frame):
                new.append(Received(self.emu.now_us, event.message, event.seq))
            else:
                self.bad.append(event)
        self.received += new
        return new

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

    def of(self, kind: type[M]) -> list[M]:
        return [r.message for r in self.received if isinstance(r.message, kind)]

    def timed(self, kind: type[M]) -> list[tuple[int, M]]:
        return [(r.time_us, r.message) for r in self.received if isinstance(r.message, kind)]

    # -- protocol steps --------------------------------------------------------------------------
    def boot(self, timeout_s: float = 3.0) -> messages.Identity:
        return self.wait_for(messages.Identity, timeout_s, lambda m: m.reason is enums.IdentityReason.BOOT)

    def hello(
        self,
        mode: enums.FeedbackMode = enums.FeedbackMode.STREAM,
        hz: int = 0,
        watchdog_ms: int = 0,
    ) -> messages.Identity:
        seq = self.send(messages.Hello(PROTOCOL_VERSION, SPEC_HASH, watchdog_ms, mode, hz))
        return self.wait_for(
            messages.Identity, 0.5, lambda m: m.hello_seq == seq and m.reason != enums.IdentityReason.BOOT
        )

    def request(self, msg: Message, seq: int | None = None, timeout_s: float = 0.5) -> Message:
        """A reliable request and its answer (ACK, NACK or the reply carrying req_seq)."""
        seq = self.send(msg, seq)

        def answers(m: Message) -> bool:
            if isinstance(m, (messages.Ack, messages.Nack)):
                return m.req_seq == seq and m.req_id == msg.MSG_ID
            return getattr(m, "req_seq", None) == seq

        return self.wait_for(Message, timeout_s, answers)

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


def raw_frame(cls: type[Message], payload: bytes, seq: int) -> bytes:
    """A valid frame (good COBS and CRC) around any payload: for values pack() refuses to encode."""
    from protocol.codec.cobs import cobs_encode
    from protocol.codec.crc import frame_crc

    body = bytes((cls.MSG_ID, seq)) + payload
    return cobs_encode(body + frame_crc(body, cls.CRC_EXTRA).to_bytes(2, "little")) + b"\x00"
