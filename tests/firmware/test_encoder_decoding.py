"""The quadrature decoder of the AVR hardware layer (arduino/RoverLink/src/hal/avr/quadrature.h).

Two independent checks:

* the native C++ unit tests (tests/firmware/native/avr_hal/test_quadrature.cpp), built with g++ -Wall
  -Wextra -Werror, once plain and once with AddressSanitizer + UndefinedBehaviorSanitizer:
  every transition of every resolution, full cycles both ways, dither, error counting, i32 wrap;
* the decoder's tables, dumped by the same binary, against a model written here from how a
  quadrature encoder moves: a shaft position, the Gray code it shows, and which edges each
  resolution counts.
"""

from __future__ import annotations

import itertools
import shutil
import subprocess
from pathlib import Path

import pytest

from tests.support import make

ROOT = Path(__file__).resolve().parents[2]
HERE = ROOT / "tests" / "firmware" / "native" / "avr_hal"
BUILD = ROOT / "build" / "native" / "avr_hal"

# Channel levels (A, B) at the four positions of one encoder cycle, turning forward (A leads B).
GRAY = ("00", "10", "11", "01")
# Edge i lies between positions i and i+1: A rises, B rises, A falls, B falls.
COUNTED_EDGES = {"X1": {0}, "X2": {0, 2}, "X4": {0, 1, 2, 3}}


def model(resolution: str, previous: str, current: str) -> str:
    """What a decoder must report for one step, from shaft positions alone."""
    start, end = GRAY.index(previous), GRAY.index(current)
    moved = (end - start) % 4
    if moved == 0:
        return "0"
    if moved == 2:
        return "INVALID"  # two edges apart: one was missed, the direction is unknowable
    if moved == 1:
        return "1" if start in COUNTED_EDGES[resolution] else "0"
    return "-1" if end in COUNTED_EDGES[resolution] else "0"


@pytest.fixture(scope="module")
def built() -> subprocess.CompletedProcess[str]:
    if shutil.which("g++") is None or shutil.which("make") is None:
        pytest.fail("g++ and make are required (scripts/test.sh installs them)", pytrace=False)
    return make.require_make(HERE, "test", build=BUILD)


def test_native_unit_tests_pass_plain_and_with_sanitizers(built: subprocess.CompletedProcess[str]) -> None:
    closing = [line for line in built.stdout.splitlines() if line.endswith(" failed")]
    assert len(closing) == 2, built.stdout  # the plain and the sanitizer build
    for line in closing:
        passed, failed = (int(word) for word in line.replace(",", "").split() if word.isdigit())
        assert failed == 0, built.stdout
        assert passed > 1000, line  # every transition, cycle and dither check ran


def test_tables_match_the_shaft_position_model(built: subprocess.CompletedProcess[str]) -> None:
    dump = subprocess.run(
        [str(BUILD / "asan" / "test_quadrature"), "--dump"], capture_output=True, text=True, timeout=60, check=True
    ).stdout.split("\n")
    rows = [line.split() for line in dump if line]
    assert len(rows) == 3 * 16, dump
    seen = set()
    for resolution, previous, current, delta in rows:
        assert delta == model(resolution, previous, current), f"{resolution} {previous} -> {current}"
        seen.add((resolution, previous, current))
    assert len(seen) == 48  # every transition of every resolution, each once


@pytest.mark.parametrize("resolution", ["X1", "X2", "X4"])
def test_model_counts_resolution_per_cycle_both_ways(resolution: str) -> None:
    """The model itself: a full cycle forward is +N counts, backward -N, for N = 1, 2, 4."""
    steps = [GRAY[i % 4] for i in range(5)]
    forward = sum(int(model(resolution, a, b)) for a, b in itertools.pairwise(steps))
    backward = sum(int(model(resolution, b, a)) for a, b in itertools.pairwise(steps))
    assert forward == int(resolution[1]) == -backward
