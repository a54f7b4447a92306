"""The firmware-in-the-loop plant loop (emulator.backends.simavr.PlantLoop) behind the Python
emulator's serial line: faults from the shared grammar and injection code, the bootloader after a
DTR or external reset, latency, crystal drift. The MCU here is a stand-in that echoes what it
receives, so no simavr is needed; tests/emulator/test_simavr_options.py runs the real firmware."""

from __future__ import annotations

import pytest

from emulator import Emulator
from emulator.backends.simavr import PHYSICS_US, RELEASED, PinState, PlantLoop
from emulator.errors import EmulatorValueError, FaultSpecError

PROFILE = "diffdrive-tb6612"


class EchoMCU:
    """Sends back every byte it receives; records its steps and resets."""

    def __init__(self, echo: bool = True) -> None:
        self.echo = echo
        self.steps: list[int] = []
        self.resets: list[int] = []
        self.loop: PlantLoop | None = None

    def step(self, us: int, counts: list[int], rx: bytes) -> tuple[PinState, bytes]:
        self.steps.append(us)
        return RELEASED, rx if self.echo else b""

    def reset(self) -> None:
        assert self.loop is not None
        self.resets.append(self.loop.now_us)


def make(echo: bool = True, **kw: object) -> tuple[PlantLoop, EchoMCU]:
    mcu = EchoMCU(echo)
    loop = PlantLoop(PROFILE, mcu, **kw)  # type: ignore[arg-type]
    mcu.loop = loop
    return loop, mcu


def round_trip(loop: PlantLoop, data: bytes, us: int) -> bytes:
    loop.host_write(data)
    out = b""
    end = loop.now_us + us
    while loop.now_us < end:
        loop.advance_us(PHYSICS_US)
        out += loop.host_read()
    return out


PAYLOAD = bytes(range(1, 256)) * 4


def test_power_on_break_then_a_clean_echo() -> None:
    loop, _ = make()
    assert round_trip(loop, PAYLOAD, 200_000) == b"\x00" + PAYLOAD


def test_line_faults_both_directions_seeded() -> None:
    def run(seed: int) -> tuple[bytes, int, int]:
        loop, _ = make(seed=seed, faults="bitflip.h2m=0.01,insert.m2h=0.01")
        out = round_trip(loop, PAYLOAD, 300_000)
        t = loop.truth
        assert t.host_to_mcu is not None and t.mcu_to_host is not None
        return out, t.host_to_mcu.bits_flipped, t.mcu_to_host.bytes_inserted

    out, flipped, inserted = run(3)
    assert flipped > 0 and inserted > 0
    assert out != b"\x00" + PAYLOAD
    assert run(3) == (out, flipped, inserted)  # same seed, same bytes
    assert run(4)[0] != out


def test_drop_and_cut_windows() -> None:
    loop, _ = make(faults="drop.h2m=1@0.01-0.02,cut.m2h@0.05-0.06")
    loop.advance_us(10_000)
    assert loop.host_read() == b"\x00"  # the power-on break
    assert round_trip(loop, b"abc", 5_000) == b""  # dropped on the way in
    loop.advance_to_us(30_000)
    assert round_trip(loop, b"abc", 5_000) == b"abc"
    loop.advance_to_us(50_000)
    assert round_trip(loop, b"abc", 5_000) == b""  # echoed into a cut line
    loop.advance_to_us(60_000)
    assert round_trip(loop, b"abc", 5_000) == b"abc"
    kinds = [f.kind for f in loop.truth.faults]
    assert kinds.count("drop") == 3 and "cut" in kinds and "restore" in kinds
    assert loop.truth.mcu_to_host is not None and loop.truth.mcu_to_host.bytes_lost_cut == 3


def test_noise_burst_puts_bytes_on_the_line() -> None:
    loop, _ = make(echo=False, seed=1, faults="noise.m2h=0.1@0.01-0.11")
    loop.advance_us(200_000)
    noise = loop.host_read()
    assert len(noise) > 50
    assert loop.truth.mcu_to_host is not None and loop.truth.mcu_to_host.noise_bytes == len(noise) - 1  # + break


def test_dtr_reset_shows_the_host_what_the_python_emulator_shows() -> None:
    """Bootloader garbage (the same bytes for the same seed: the code is shared), host bytes lost
    while the MCU is in the bootloader, the sketch starting after bootloader_ms with a break."""
    emu = Emulator(PROFILE, 5, latency_us=0, bootloader_ms=300)
    emu.advance(0.5)
    emu.host_read()
    emu.dtr_reset()
    emu.advance(0.302)
    python_bytes = emu.host_read()

    loop, mcu = make(echo=False, seed=5, bootloader_ms=300)
    loop.advance_us(500_000)
    loop.host_read()
    loop.dtr_reset()
    loop.host_write(b"lost in the bootloader")
    loop.advance_us(299_000)
    assert loop.truth.in_reset and mcu.resets == []
    loop.advance_us(1_000)
    assert mcu.resets == [800_000] and not loop.truth.in_reset
    loop.advance_us(1_000)
    garbage = loop.host_read()
    assert 2 <= len(garbage) <= 5 and garbage.endswith(b"\x00")
    assert garbage == python_bytes[: len(garbage)]
    assert loop.bytes_lost_in_reset == len(b"lost in the bootloader")
    assert [f.kind for f in loop.truth.faults] == ["dtr_reset", "bootloader_garbage"]


def test_reset_and_brownout_items() -> None:
    timing = PlantLoop(PROFILE, EchoMCU()).profile.plant.timing
    loop, mcu = make(faults="reset@0.1,brownout=30@2.0,dtr@3.0")
    loop.advance_us(5_000_000)
    assert mcu.resets == [
        100_000 + timing.bootloader_ms * 1000,
        2_000_000 + 30_000 + timing.power_on_ms * 1000,
        3_000_000 + timing.bootloader_ms * 1000,
    ]
    kinds = [f.kind for f in loop.truth.faults]
    assert kinds == ["reset", "bootloader_garbage", "brownout", "dtr_reset", "bootloader_garbage"]
    assert loop.truth.resets == 3


def test_stall_and_encoder_items_reach_the_shared_plant() -> None:
    loop, _ = make(faults="stall=1@0.01-0.02,encoder=0@0.01,traction=0.1@0.01")
    loop.advance_us(15_000)
    assert loop.truth.stalled == (False, True) and loop.truth.encoder_connected == (False, True)
    assert loop.plant.vehicle.mu == 0.1
    loop.advance_us(10_000)
    assert loop.truth.stalled == (False, False) and loop.truth.encoder_connected == (False, True)


@pytest.mark.parametrize(
    ("spec", "problem"),
    [("eeprom@1", "EEPROM"), ("stall=1@1", "wheel must be 0..0"), ("bitflip=2", "probability")],
)
def test_refused_items_name_the_item_and_why(spec: str, problem: str) -> None:
    profile = "picar" if spec.startswith("stall") else PROFILE
    with pytest.raises(FaultSpecError) as err:
        PlantLoop(profile, EchoMCU(), faults=spec)
    assert spec in str(err.value) and problem in str(err.value)


def test_latency_each_way() -> None:
    loop, _ = make(latency_us=3000)
    loop.advance_us(10_000)
    assert loop.host_read() == b"\x00"
    loop.host_write(b"x")
    waited = 0
    while not loop.host_read():
        loop.advance_us(PHYSICS_US)
        waited += PHYSICS_US
    assert 6_000 <= waited <= 8_000


def test_drift_runs_the_mcu_clock_fast_or_slow() -> None:
    for ppm, expected in ((0, 1_000_000), (2500, 1_002_500), (-400, 999_600)):
        loop, mcu = make(drift_ppm=ppm)
        loop.advance_us(1_000_000)
        assert sum(mcu.steps) == expected
        assert max(mcu.steps) - min(mcu.steps) <= 3


@pytest.mark.parametrize(
    ("option", "value"), [("latency_us", -1), ("drift_ppm", float("nan")), ("bootloader_ms", 60_001)]
)
def test_both_backends_refuse_a_bad_board_option_by_name(option: str, value: object) -> None:
    for backend in (lambda: Emulator("picar", **{option: value}), lambda: make(**{option: value})):
        with pytest.raises(EmulatorValueError, match=option):
            backend()
