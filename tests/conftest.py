"""Shared pytest configuration: the lanes, the per-test timeout and the Hypothesis profiles.

Lanes (docs/testing.md):

* the fast lane (``scripts/test.sh --quick``, ``-m "not slow"``) is the unit tests: every test under
  one of QUICK_FOLDERS that is not marked ``slow`` (a module says ``pytestmark = pytest.mark.slow``);
  everything else is marked ``slow`` here at collection;
* ``serial`` tests need the whole machine (a real browser, rates measured on the wall clock, the
  benchmarks' figures): the full run gives them a process of their own after the parallel part.

Hypothesis profiles, chosen with the HYPOTHESIS_PROFILE environment variable:

* ``ci`` (default): 100 examples per property, no deadline; quick enough for every push.
* ``thorough``: 2000 examples per property, for a nightly run or after touching the codec.

    HYPOTHESIS_PROFILE=thorough pytest -q tests/protocol/codec
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

try:
    from hypothesis import HealthCheck, settings
except ImportError:  # hypothesis is a dev extra: suites that do not use it still run without it
    settings = None  # type: ignore[assignment,misc]

PROFILE_ENV = "HYPOTHESIS_PROFILE"
PROFILE = os.environ.get(PROFILE_ENV, "ci")

if settings is not None:
    settings.register_profile(
        "ci",
        max_examples=100,
        deadline=None,
        derandomize=False,
        suppress_health_check=[HealthCheck.too_slow],
    )
    settings.register_profile(
        "thorough",
        max_examples=2000,
        deadline=None,
        derandomize=False,
        suppress_health_check=[HealthCheck.too_slow],
    )
    settings.load_profile(PROFILE)


ROOT = Path(__file__).resolve().parent.parent
QUICK_FOLDERS = (
    "tests/protocol",
    "tests/host_sdk",
    "tests/emulator",
    "tests/roverlink/cli",
    "tests/system/architecture",
)
"""Where the unit tests are: in-process, on the virtual clock, no compiler, no simulator, no browser."""
SERIAL_FOLDERS = ("tests/roverlink/console",)
"""Suites that need the machine to themselves (Debian's Chromium driving the console on the wall clock)."""


def _under(item: pytest.Item, folders: tuple[str, ...]) -> bool:
    rel = Path(item.path).resolve().relative_to(ROOT).as_posix()
    return any(rel == f or rel.startswith(f"{f}/") for f in folders)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if not _under(item, QUICK_FOLDERS):
            item.add_marker(pytest.mark.slow)
        if _under(item, SERIAL_FOLDERS):
            item.add_marker(pytest.mark.serial)


def pytest_report_header() -> str:
    if settings is None:
        return "hypothesis: not installed"
    return f"hypothesis profile: {PROFILE} (set {PROFILE_ENV} to change)"
