"""Shared pytest configuration: the lanes, the per-test timeout and the Hypothesis profiles.

Lanes (docs/testing.md):

* the fast lane (``scripts/test.sh --quick``, ``-m "not slow"``) is the unit tests: every test under
  one of QUICK_FOLDERS but not in SLOW_MODULES (nor marked ``slow`` itself); everything else is
  marked ``slow`` here at collection;
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
SLOW_MODULES = (
    # processes and ptys on the wall clock: roverlink emulate, the examples, pytest and mypy in a subprocess
    "tests/emulator/test_transport.py",
    "tests/emulator/sensors/test_sensor_failure.py",
    "tests/host_sdk/sensors/test_sensor_pty.py",
    "tests/host_sdk/test_sdk_examples.py",
    "tests/host_sdk/test_sdk_testing.py",
    "tests/host_sdk/test_sdk_typing.py",
    "tests/host_sdk/autonomy/test_follow_example.py",
    "tests/host_sdk/console/test_console_example.py",
    "tests/roverlink/cli/test_missing_extras.py",
    "tests/roverlink/cli/test_emulate_log.py",
    # the firmware in simavr
    "tests/emulator/test_simavr_options.py",
    "tests/emulator/test_simavr_robotfile.py",
    "tests/emulator/test_simavr_wiring.py",
    # long closed-loop runs: the tracker on real-photo sequences (the EKF's minutes of driving are
    # marked slow where they are)
    "tests/host_sdk/autonomy/test_tracking_photos.py",
)
"""Modules under QUICK_FOLDERS that are not unit tests: they stay out of the fast lane."""
SERIAL_FOLDERS = (
    # Debian's Chromium driving the console; ROS 2 nodes and the tools on the wall clock, with rates
    # and watchdogs that a second busy core would starve
    "tests/roverlink/console",
    "tests/roverlink/ros2",
    "tests/roverlink/tools",
    "tests/roverlink/follow",
    "tests/system/integration",
    # the firmware's budgets: simavr's speed against the wall clock
    "tests/system/conformance/test_firmware_budgets.py",
    # roverlink emulate and the examples on the wall clock
    "tests/emulator/test_transport.py",
    "tests/emulator/sensors/test_sensor_failure.py",
    "tests/host_sdk/sensors/test_sensor_pty.py",
    "tests/host_sdk/test_sdk_examples.py",
    "tests/host_sdk/console/test_console_example.py",
    "tests/roverlink/cli/test_emulate_log.py",
)
"""Suites that need the machine to themselves: the full run gives them one pytest process after the rest."""


def _under(item: pytest.Item, folders: tuple[str, ...]) -> bool:
    rel = Path(item.path).resolve().relative_to(ROOT).as_posix()
    return any(rel == f or rel.startswith(f"{f}/") for f in folders)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if not _under(item, QUICK_FOLDERS) or _under(item, SLOW_MODULES):
            item.add_marker(pytest.mark.slow)
        if _under(item, SERIAL_FOLDERS):
            item.add_marker(pytest.mark.serial)


def pytest_report_header() -> str:
    if settings is None:
        return "hypothesis: not installed"
    return f"hypothesis profile: {PROFILE} (set {PROFILE_ENV} to change)"
