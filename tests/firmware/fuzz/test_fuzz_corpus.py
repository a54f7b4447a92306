"""The committed fuzz corpora replayed through the fuzz targets (tests/firmware/fuzz/Makefile `replay`).

Every input in tests/firmware/fuzz/corpus/ runs once through its target, built with ASan, UBSan and the
target's invariants: a regression that an earlier fuzzing run would have caught fails here, in an
ordinary test run. Needs clang 14 (scripts/fuzz.sh installs it; it also fuzzes for real).
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from tests.support import make

ROOT = Path(__file__).resolve().parents[3]
TARGETS = ("decoder", "firmware", "config")

needs_clang = pytest.mark.skipif(
    shutil.which("clang++-14") is None and shutil.which("clang++") is None,
    reason="needs clang 14 with libFuzzer (bash scripts/fuzz.sh installs it)",
)


def test_every_target_has_a_corpus() -> None:
    for target in TARGETS:
        assert len(list((ROOT / "tests" / "firmware" / "fuzz" / "corpus" / target).iterdir())) >= 3, target


@needs_clang
def test_the_committed_corpora_pass_every_invariant() -> None:
    run = make.make(ROOT / "tests" / "firmware" / "fuzz", "-s", "-j2", "replay")
    print(run.stdout)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    passed = dict(re.findall(r"fuzz_(\w+): (\d+) corpus inputs pass", run.stdout))
    assert set(passed) == set(TARGETS) and all(int(n) > 0 for n in passed.values()), run.stdout
