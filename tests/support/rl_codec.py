"""The C++ codec's line-oriented driver (tests/firmware/native/rl_codec.cpp) behind a pipe, the text
form its `print_fields` uses, and the Python side of a byte-for-byte comparison with it."""

from __future__ import annotations

import itertools
import os
import re
import select
import struct
import subprocess
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import pytest
from hypothesis import event as label_example

from host_sdk import messages
from host_sdk.framing import BadFrame, Frame, FrameDecoder
from protocol.codec.message import FieldInfo, Message
from protocol.generated.structs import DECODER_COUNTERS
from tests.support import make
from tests.support.wait import Deadline

ROOT = Path(__file__).resolve().parents[2]
NATIVE_DIR = ROOT / "tests" / "firmware" / "native"
BUILD = ROOT / "build" / "native"
RL_CODEC = BUILD / "asan" / "rl_codec"
VECTOR_DIR = ROOT / "protocol" / "vectors"

ANSWER_TIMEOUT_S = 30.0

BY_NAME: dict[str, type[Message]] = {cls.NAME: cls for cls in messages.ALL_MESSAGES}
STAT_NAMES = DECODER_COUNTERS


# -- the text form of print_fields ----------------------------------------------------------------
def _f32_bits(value: float) -> int:
    bits: int = struct.unpack("<I", struct.pack("<f", value))[0]
    return bits


def _scalar_text(info: FieldInfo, value: Any) -> str:
    if info.kind == "float":
        return f"0x{_f32_bits(value):08X}"
    return str(int(value))  # ints, and enums and flags by value


def field_text(info: FieldInfo, value: Any) -> str:
    """One field as print_fields writes it (and as set_field reads it)."""
    if info.kind == "str":
        return str(value).encode("ascii").hex()
    if info.kind == "bytes":
        return bytes(value).hex()
    if info.count is not None:
        return ",".join(_scalar_text(info, v) for v in value)
    return _scalar_text(info, value)


def field_pairs(msg: Message) -> list[str]:
    return [f"{info.name}={field_text(info, getattr(msg, info.name))}" for info in msg.FIELDS]


def canonical(msg: Message) -> str:
    """What the C++ `reflect::print_fields(f, m)` prints for the same message: "NAME a=1 b=2"."""
    return " ".join([msg.NAME, *field_pairs(msg)])


def frame_item(msg: Message, seq: int) -> str:
    """The rl_codec event item for a good frame: F:<NAME>:<seq>:<fields joined by ';'>."""
    name, _, fields = canonical(msg).partition(" ")
    return f"F:{name}:{seq}:{fields.replace(' ', ';')}"


_F32_TEXT = re.compile(r"0x([0-9A-F]{8})")


def _quiet_nan(match: re.Match[str]) -> str:
    bits = int(match.group(1), 16)
    if bits & 0x7F800000 == 0x7F800000 and bits & 0x007FFFFF:
        bits |= 0x00400000
    return f"0x{bits:08X}"


def quiet_nans(item: str) -> str:
    """Sets the quiet bit of every f32 NaN in an item's text.

    A Python float cannot hold a signalling NaN: unpacking one sets its quiet bit. That is the
    host's float model, not a codec difference, so items are compared with NaNs quietened.
    """
    return _F32_TEXT.sub(_quiet_nan, item)


# -- rl_codec behind a pipe --------------------------------------------------------------------------
def require_make(*targets: str) -> subprocess.CompletedProcess[str]:
    """`make -C tests/firmware/native TARGETS` into build/native, failing the test when it fails."""
    return make.require_make(NATIVE_DIR, *targets, build=BUILD)


@dataclass
class Decoded:
    items: list[str]
    stats: dict[str, int]


class RlCodec:
    """One rl_codec process: a command line in, exactly one answer line out."""

    def __init__(self, path: Path, stderr: IO[bytes]) -> None:
        env = dict(os.environ)
        env["ASAN_OPTIONS"] = "detect_leaks=1:abort_on_error=1"
        env["UBSAN_OPTIONS"] = "print_stacktrace=1:halt_on_error=1"
        self._stderr = stderr
        self.proc = subprocess.Popen(
            [str(path)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=stderr, env=env, bufsize=0
        )
        self._buf = b""

    def stderr_text(self) -> str:
        self._stderr.flush()
        self._stderr.seek(0)
        return self._stderr.read().decode(errors="replace")

    def ask(self, command: str) -> str:
        assert "\n" not in command
        assert self.proc.stdin is not None
        try:
            self.proc.stdin.write(command.encode("ascii") + b"\n")
        except BrokenPipeError:
            pytest.fail(f"rl_codec is gone (exit {self.proc.poll()}):\n{self.stderr_text()}", pytrace=False)
        return self._read_line(command)

    def _read_line(self, command: str) -> str:
        assert self.proc.stdout is not None
        fd = self.proc.stdout.fileno()
        deadline = Deadline(ANSWER_TIMEOUT_S)
        while b"\n" not in self._buf:
            if deadline.expired():
                pytest.fail(f"rl_codec did not answer {command[:200]!r} within {ANSWER_TIMEOUT_S} s", pytrace=False)
            ready, _, _ = select.select([fd], [], [], deadline.remaining())
            if not ready:
                continue
            chunk = os.read(fd, 1 << 16)
            if not chunk:
                self.proc.wait(timeout=10)
                pytest.fail(
                    f"rl_codec exited ({self.proc.returncode}) on {command[:200]!r}:\n{self.stderr_text()}",
                    pytrace=False,
                )
            self._buf += chunk
        line, _, self._buf = self._buf.partition(b"\n")
        return line.decode("ascii")

    # Commands.
    def decode(self, data: bytes, *, streaming: bool = False) -> Decoded:
        answer = self.ask(f"{'DS' if streaming else 'D'} {data.hex()}")
        return parse_events(answer)

    def reset_stream(self) -> None:
        assert self.ask("R") == "OK"

    def encode(self, msg: Message, seq: int) -> str:
        return self.ask(" ".join(["E", msg.NAME, str(seq), *field_pairs(msg)]))

    def check_ranges(self, name: str, pairs: list[str]) -> int:
        answer = self.ask(" ".join(["C", name, *pairs])).split()
        assert answer[0] == "RANGE" and len(answer) == 2, answer
        return int(answer[1])

    def step(self, state: int, event: int, guards: int) -> tuple[bool, int, int]:
        answer = self.ask(f"S {state} {event} {guards}").split()
        assert answer[0] == "STEP" and len(answer) == 4, answer
        return answer[1] == "1", int(answer[2]), int(answer[3])

    def quit(self) -> int:
        assert self.ask("Q") == "BYE"
        return self.proc.wait(timeout=30)


def parse_events(answer: str) -> Decoded:
    """EVENTS <item> ... STATS k=v ... -> items (overlong normalised to cobs) and counters."""
    tokens = answer.split(" ")
    assert tokens[0] == "EVENTS", answer
    stats_at = tokens.index("STATS")
    items = ["E:cobs" if item == "E:overlong" else item for item in tokens[1:stats_at]]
    stats = {}
    for pair in tokens[stats_at + 1 :]:
        key, _, value = pair.partition("=")
        stats[key] = int(value)
    assert tuple(stats) == STAT_NAMES, answer
    return Decoded(items, stats)


# -- the Python side of a comparison ----------------------------------------------------------------
def python_decode(parts: list[bytes]) -> tuple[list[Frame | BadFrame], FrameDecoder]:
    decoder = FrameDecoder()
    events: list[Frame | BadFrame] = []
    for part in parts:
        events.extend(decoder.feed(part))
    return events, decoder


def python_items(events: list[Frame | BadFrame]) -> list[str]:
    items = []
    for event in events:
        if isinstance(event, Frame):
            items.append(frame_item(event.message, event.seq))
        else:
            items.append(f"E:{event.kind.value}")
    return items


def expected_cpp_stats(decoder: FrameDecoder) -> dict[str, int]:
    """The C++ decoder's counters must equal the Python decoder's, one for one."""
    return {name: getattr(decoder.stats, name) for name in STAT_NAMES}


def split(data: bytes, cuts: list[int]) -> list[bytes]:
    points = sorted({c % (len(data) + 1) for c in cuts})
    bounds = [0, *points, len(data)]
    return [data[a:b] for a, b in itertools.pairwise(bounds)]


def assert_decoders_agree(codec: RlCodec, data: bytes, cuts: list[int]) -> None:
    """Both decoders on `data`: whole, and (streaming) in the pieces `cuts` makes."""
    parts = split(data, cuts)
    events, decoder = python_decode([data])
    chunked_events, chunked_decoder = python_decode(parts)
    want_items = [quiet_nans(i) for i in python_items(events)]
    want_stats = expected_cpp_stats(decoder)
    # The Python decoder itself must not depend on how the bytes were chunked.
    assert python_items(chunked_events) == python_items(events)
    assert chunked_decoder.stats == decoder.stats

    for kind in sorted({item.split(":")[0] if item.startswith("F") else item for item in want_items}):
        label_example(f"stream has {kind}")
    whole = codec.decode(data)
    assert [quiet_nans(i) for i in whole.items] == want_items, f"stream {data.hex()}"
    assert whole.stats == want_stats, f"stream {data.hex()}"

    codec.reset_stream()
    items: list[str] = []
    stats: dict[str, int] = {}
    for part in parts:
        got = codec.decode(part, streaming=True)
        items += got.items
        stats = got.stats
    assert [quiet_nans(i) for i in items] == want_items, f"stream {data.hex()} in parts {[p.hex() for p in parts]}"
    assert stats == want_stats, f"stream {data.hex()} in parts {[p.hex() for p in parts]}"
