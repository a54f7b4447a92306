"""Shared pytest configuration: the lanes, the per-test timeout and the Hypothesis profiles.

Lanes (docs/testing.md):

* the fast lane (``scripts/test.sh --quick``, ``-m "not slow"``) is the unit tests: every test under
  one of QUICK_FOLDERS but not in SLOW_MODULES (nor marked ``slow`` itself); everything else is
  marked ``slow`` here at collection;
* ``serial`` tests need the whole machine (a real browser, rates measured on the wall clock, the
  benchmarks' figures): the full run gives them a process of their own after the parallel part.

Hypothesis profiles, chosen with the HYPOTHESIS_PROFILE environment variable:

* ``ci`` (default): 100 examples per property, no deadline; quick enough for every push.
* ``interpreters``: 20 examples per property, for the other Pythons' runs (scripts/test_pythons.sh),
  which look for what an interpreter changes, not for new inputs;
* ``thorough``: 2000 examples per property, for a nightly run or after touching the codec.

    HYPOTHESIS_PROFILE=thorough pytest -q tests/protocol/codec
"""

from __future__ import annotations

import os
from fnmatch import fnmatch
from pathlib import Path

import pytest

try:
    from hypothesis import HealthCheck, settings
except ImportError:  # hypothesis is a dev extra: suites that do not use it still run without it
    settings = None  # type: ignore[assignment,misc]

PROFILE_ENV = "HYPOTHESIS_PROFILE"
PROFILE = os.environ.get(PROFILE_ENV, "ci")

PROFILE_EXAMPLES = {"ci": 100, "interpreters": 20, "thorough": 2000}

if settings is not None:
    for name, examples in PROFILE_EXAMPLES.items():
        settings.register_profile(
            name,
            max_examples=examples,
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
    "tests/host_sdk/supervisor/test_supervisor_connection.py",
    # the firmware in simavr
    "tests/emulator/test_simavr_options.py",
    "tests/emulator/test_simavr_robotfile.py",
    "tests/emulator/test_simavr_wiring.py",
    # the Pico firmware in rp2040js, served on a pty
    "tests/emulator/test_rp2040_emulate.py",
    # the distribution's Python only (scripts/test_system_opencv.sh runs it)
    "tests/host_sdk/sensors/test_camera_system_opencv.py",
    # long closed-loop runs: the tracker on real-photo sequences (the EKF's minutes of driving are
    # marked slow where they are)
    "tests/host_sdk/autonomy/test_tracking_photos.py",
)
"""Modules under QUICK_FOLDERS that are not unit tests: they stay out of the fast lane."""
SERIAL_MODULES = (
    # Debian's Chromium driving the console, and the console on ptys
    "tests/roverlink/console",
    # ROS 2 nodes on the wall clock: rates and watchdogs that a second busy core would starve
    "tests/roverlink/ros2/test_bridge*.py",
    "tests/roverlink/ros2/test_bringup_launch.py",
    "tests/roverlink/ros2/test_sensor_thread.py",
    # the tools, roverlink follow and roverlink emulate on ptys and the wall clock
    "tests/roverlink/tools/test_tools_calibrate.py",
    "tests/roverlink/tools/test_tools_monitor_teleop.py",
    "tests/roverlink/tools/test_tools_sensors.py",
    "tests/roverlink/follow/test_follow_metrics.py",
    "tests/roverlink/follow/test_follow_robot.py",
    "tests/roverlink/cli/test_emulate_log.py",
    "tests/emulator/test_rp2040_emulate.py",
    "tests/system/integration/test_integration_pty.py",
    "tests/system/integration/test_integration_robot_file.py",
    "tests/emulator/test_transport.py",
    "tests/host_sdk/sensors/test_sensor_pty.py",
    "tests/host_sdk/test_sdk_examples.py",
    "tests/host_sdk/console/test_console_example.py",
    "tests/host_sdk/supervisor/test_supervisor_connection.py",
)
"""Suites that need the machine to themselves: the full run gives them one pytest process after the rest."""


def _rel_under(rel: str, paths: tuple[str, ...]) -> bool:
    return any(fnmatch(rel, p) or rel.startswith(f"{p}/") for p in paths)


def _under(item: pytest.Item, paths: tuple[str, ...]) -> bool:
    """Whether the item's module is one of `paths` (folders, files or glob patterns) or under one."""
    return _rel_under(Path(item.path).resolve().relative_to(ROOT).as_posix(), paths)


def _slow_module(rel: str) -> bool:
    return not _rel_under(rel, QUICK_FOLDERS) or _rel_under(rel, SLOW_MODULES)


def pytest_ignore_collect(collection_path: Path, config: pytest.Config) -> bool | None:
    """With `-m "not slow"` (the fast lane), modules that are slow as a whole are not even
    imported: the same selection, without their import-time skips (ROS 2, the distribution's
    OpenCV) in a lane that never runs them."""
    if config.getoption("markexpr", "") != "not slow":
        return None
    try:
        rel = collection_path.resolve().relative_to(ROOT).as_posix()
    except ValueError:
        return None
    if rel == ".":
        return None
    if collection_path.is_dir():  # keep the folders on the way to, or inside, a quick folder
        return None if any(q.startswith(f"{rel}/") or _rel_under(rel, (q,)) for q in QUICK_FOLDERS) else True
    return True if collection_path.suffix == ".py" and _slow_module(rel) else None


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if _slow_module(Path(item.path).resolve().relative_to(ROOT).as_posix()):
            item.add_marker(pytest.mark.slow)
        if _under(item, SERIAL_MODULES):
            item.add_marker(pytest.mark.serial)


def pytest_report_header() -> str:
    if settings is None:
        return "hypothesis: not installed"
    return f"hypothesis profile: {PROFILE} (set {PROFILE_ENV} to change)"
