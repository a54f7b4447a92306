"""The rp2040js harness itself (tools/rp2040/harness.mjs, emulator.backends.rp2040), checked with a
firmware small enough to be obviously right (tests/firmware/rp2040/harness_check.cpp), so that a
harness fault is never read as a firmware fault: UART bytes both ways at the baud rate, PWM duty
read back from the pin, quadrature edges counted by the chip's edge interrupts, the chip's
microsecond timer against the harness's clock, and a reset."""

from __future__ import annotations

import os
import shutil
import struct
from collections.abc import Iterator
from pathlib import Path

import pytest

from emulator.backends.rp2040 import Harness, Rp2040Error
from emulator.backends.rp2040.harness import BUILD_DIR, HARNESS_DIR, node_modules
from tests.support.make import require_make

ENCODER = (4, 5)
PWM_A, PWM_B = 2, 3
IMAGE = BUILD_DIR / "harness_check.bin"


def _require() -> None:
    problem = None
    if shutil.which("arm-none-eabi-g++") is None:
        problem = "Debian's gcc-arm-none-eabi and libnewlib-arm-none-eabi"
    elif shutil.which("node") is None:
        problem = "Node.js (Debian's nodejs and npm)"
    else:
        try:
            node_modules()
        except Rp2040Error as exc:
            problem = str(exc)
    if problem is None:
        return
    if os.environ.get("ROVERLINK_REQUIRE_RP2040"):
        pytest.fail(f"the RP2040 backend's tests need {problem} (scripts/test.sh installs them)", pytrace=False)
    pytest.skip(f"needs {problem}")


@pytest.fixture
def chip() -> Iterator[Harness]:
    _require()
    require_make(HARNESS_DIR, build=BUILD_DIR)
    with Harness(Path(IMAGE), encoders=(ENCODER,), watch=(PWM_A, PWM_B)) as harness:
        harness.step(2000, [0], b"")  # the firmware's set-up
        yield harness


def counted(chip: Harness, position: int) -> tuple[int, int]:
    """The edges the firmware counted on the encoder's two pins (asked after the step's edges)."""
    chip.step(1000, [position], b"")
    _, tx = chip.step(1000, [position], b"\xff")
    a, b = struct.unpack("<II", tx)
    return a, b


def test_uart_bytes_go_both_ways_at_the_baud_rate(chip: Harness) -> None:
    _, tx = chip.step(1000, [0], b"RoverLink")
    assert tx == b"RoverLink"  # 9 bytes in 781 us at 115200 baud, echoed in the same step
    _, tx = chip.step(500, [0], bytes(range(60)))  # 5.2 ms of bytes: a 500 us step carries 5
    rest = b"".join(chip.step(1000, [0], b"")[1] for _ in range(6))
    assert tx + rest == bytes(range(60))
    assert 0 < len(tx) < 60


def test_pwm_duty_is_read_back_from_the_pins(chip: Harness) -> None:
    pins, _ = chip.step(10_000, [0], b"")  # ten periods of the 1 kHz slice
    assert pins[PWM_A].high == pytest.approx(0.25, abs=1e-3)
    assert pins[PWM_B].high == pytest.approx(0.60, abs=1e-3)


def test_quadrature_edges_are_counted_by_the_chips_interrupts(chip: Harness) -> None:
    assert counted(chip, 1) == (1, 0)  # A rises
    assert counted(chip, 2) == (1, 1)  # then B
    assert counted(chip, -3) == (3, 4)  # five counts back: B, A, B, A, B
    assert counted(chip, 97) == (53, 54)  # a hundred forwards in one step


def test_the_chips_microsecond_timer_keeps_the_harness_time(chip: Harness) -> None:
    _, tx = chip.step(1000, [0], b"\xfe")
    first = struct.unpack("<I", tx)[0]
    chip.step(25_000, [0], b"")
    _, tx = chip.step(1000, [0], b"\xfe")
    assert struct.unpack("<I", tx)[0] - first == 26_000  # each asked 87 us into its step


def test_a_reset_starts_the_image_again(chip: Harness) -> None:
    counted(chip, 2)
    chip.reset()
    chip.step(2000, [2], b"")
    assert chip.resets == 1
    assert counted(chip, 2) == (0, 0)  # the counts start again; the pins stayed where they were
    _, tx = chip.step(1000, [2], b"ok")
    assert tx == b"ok"


def noise(chip: Harness) -> int:
    _, tx = chip.step(1000, [0], b"\xfd")
    return int(struct.unpack("<I", tx)[0])


def test_the_ring_oscillators_noise_differs_by_seed_and_read_by_read() -> None:
    """The boot_id's entropy on the RP2040: rp2040js has no ring oscillator, the harness serves its
    RANDOMBIT from a seeded generator; the same seed gives the same bits, another seed others, and
    the bits go on across a reset (a board's second boot draws a new boot_id)."""
    _require()
    require_make(HARNESS_DIR, build=BUILD_DIR)
    drawn = {}
    for seed in (1, 2, 1):
        with Harness(Path(IMAGE), seed=seed) as chip:
            chip.step(2000, [], b"")
            first, second = noise(chip), noise(chip)
            chip.reset()
            chip.step(2000, [], b"")
            after_reset = noise(chip)
        assert len({first, second, after_reset}) == 3, (seed, first, second, after_reset)
        assert drawn.setdefault(seed, (first, second, after_reset)) == (first, second, after_reset)
    assert drawn[1] != drawn[2]


def test_an_image_path_is_the_callers_and_a_missing_one_is_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The harness runs in tools/rp2040; the image's path is taken from where the caller stands."""
    _require()
    require_make(HARNESS_DIR, build=BUILD_DIR)
    monkeypatch.chdir(IMAGE.parent)
    with Harness(Path(IMAGE.name)) as harness:
        harness.step(2000, [], b"")
    with pytest.raises(Rp2040Error, match=r"no RP2040 image .*nothing\.bin \(roverlink firmware build"):
        Harness(tmp_path / "nothing.bin")
