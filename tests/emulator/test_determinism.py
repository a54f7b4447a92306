"""Same seed and same input bytes at the same virtual times => the same output bytes and ground truth."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from emulator import Emulator, Truth
from host_sdk import enums, messages
from host_sdk.framing import encode_frame
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH

FAULTS = "bitflip=5e-4,drop=5e-4,insert=5e-4,noise@1.0-1.05,stall=0@1.5-1.7,reset@2.2,brownout=30@3.4"


def _script(boot_id: int) -> list[tuple[int, bytes]]:
    hello = messages.Hello(PROTOCOL_VERSION, SPEC_HASH, 0, enums.FeedbackMode.STREAM, 100)
    script = [(200_000, encode_frame(hello, 0)), (250_000, encode_frame(messages.Arm(boot_id), 1))]
    for k in range(150):
        msg = messages.SetWheelSpeeds(300 - 2 * k, 200 + k) if k % 7 else messages.Ping(k)
        script.append((300_000 + 20_000 * k, encode_frame(msg, (2 + k) & 0xFF)))
    return script


def _run(seed: int, script: list[tuple[int, bytes]], end_us: int = 4_000_000, step_us: int = 0) -> tuple[bytes, Truth]:
    emu = Emulator("diffdrive-tb6612", seed=seed, faults=FAULTS)
    out = bytearray()
    for at, data in script:
        if step_us:
            while emu.now_us + step_us < at:
                emu.advance_us(step_us)
                out += emu.host_read()
        emu.advance_to_us(at)
        emu.host_write(data)
        out += emu.host_read()
    emu.advance_to_us(end_us)
    out += emu.host_read()
    return bytes(out), emu.truth


def _boot_id(seed: int) -> int:
    emu = Emulator("diffdrive-tb6612", seed=seed)
    emu.advance(0.2)
    return emu.boot_ids[0]


def test_same_seed_same_bytes_same_truth() -> None:
    script = _script(_boot_id(7))
    out1, truth1 = _run(7, script)
    out2, truth2 = _run(7, script)
    assert out1 == out2 and truth1 == truth2
    assert len(out1) > 5_000 and truth1.mcu.resets == 2 and truth1.host_to_mcu.bits_flipped > 0
    # How time is advanced (one call, or 1 ms at a time while reading) changes nothing.
    out3, truth3 = _run(7, script, step_us=1000)
    assert out3 == out1 and truth3 == truth1


def test_another_seed_gives_another_boot_and_other_noise() -> None:
    assert _boot_id(7) != _boot_id(8)
    script = _script(_boot_id(7))
    out1, truth1 = _run(7, script)
    out2, truth2 = _run(8, script)
    assert out1 != out2
    assert truth1.mcu.boot_ids != truth2.mcu.boot_ids
    assert [f.detail for f in truth1.faults if f.kind == "bitflip"] != [
        f.detail for f in truth2.faults if f.kind == "bitflip"
    ]


@settings(max_examples=15, deadline=None)
@given(
    seed=st.integers(0, 1000),
    chunks=st.lists(st.tuples(st.integers(0, 50_000), st.binary(max_size=40)), max_size=12),
)
def test_any_input_is_reproducible(seed: int, chunks: list[tuple[int, bytes]]) -> None:
    script = []
    t = 100_000
    for gap, data in chunks:
        t += gap
        script.append((t, data))
    assert _run(seed, script, end_us=t + 300_000) == _run(seed, script, end_us=t + 300_000)
