"""pytest fixtures for testing robot code against the emulator (registered as the `roverlink` plugin).

    def test_drives_forward(robot, emulator):
        robot.arm()
        for _ in range(50):
            robot.drive(0.3, 0.0)
            robot.sleep(0.02)             # virtual time: instant, deterministic
        assert emulator.truth.plant.x_m > 0.2

Fixtures:

- `robot`: a `host_sdk.Robot` connected to an in-process emulator on a virtual clock, ready
  (disarmed unless `armed=True`). Time passes only while it waits: `robot.sleep(s)`,
  `robot.wait_feedback()`, requests. No threads, so runs are reproducible from the seed.
- `emulator`: the `emulator.Emulator` behind it: `.truth` (ground truth: pose, wheel speeds,
  firmware state), fault injection (`cut_link()`, `reset_mcu()`, `set_drop_rate()`, ...).
  Calling `emulator.advance(s)` directly runs the robot while the host is frozen (the watchdog acts).
- `roverlink_options`: the dict the fixtures are built from; override it in a conftest.py, or set
  fields per test with `@pytest.mark.roverlink(profile="picar", seed=3, faults="drop=1e-3",
  mode="lockstep", armed=True, watchdog_s=0.5, ...)`. Keys other than profile, seed, faults,
  armed and eeprom go to `Robot.connect`.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any
from urllib.parse import quote

import pytest

from host_sdk.robot import Robot

DEFAULTS: dict[str, Any] = {"profile": "diffdrive-tb6612", "seed": 0, "faults": "", "armed": False, "eeprom": "saved"}


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        "roverlink(profile=..., seed=..., faults=..., mode=..., armed=..., **connect_options): "
        "configure the emulated `robot` and `emulator` fixtures of the roverlink plugin",
    )


def emulator_url(profile: str, seed: int = 0, faults: str = "", eeprom: str = "saved") -> str:
    """The emu:// URL of a virtual-clock emulator."""
    url = f"emu://{profile}?seed={seed}&clock=virtual&eeprom={eeprom}"
    if faults:
        url += "&faults=" + quote(faults, safe=",")
    return url


@pytest.fixture
def roverlink_options(request: pytest.FixtureRequest) -> dict[str, Any]:
    """Options of the emulated robot: DEFAULTS, updated by a @pytest.mark.roverlink(...) on the test."""
    options = dict(DEFAULTS)
    for marker in reversed(list(request.node.iter_markers("roverlink"))):
        options.update(marker.kwargs)
    return options


@pytest.fixture
def robot(roverlink_options: dict[str, Any]) -> Iterator[Robot]:
    """A Robot on an in-process emulator with a virtual clock, connected and ready."""
    options = dict(roverlink_options)
    profile = options.pop("profile")
    url = emulator_url(profile, options.pop("seed"), options.pop("faults"), options.pop("eeprom"))
    armed = options.pop("armed")
    bot = Robot.connect(url, profile=profile, **options)
    try:
        if armed:
            bot.arm()
        yield bot
    finally:
        bot.close()


@pytest.fixture
def emulator(robot: Robot) -> Any:
    """The emulator.Emulator behind `robot`: ground truth (`.truth`) and fault injection."""
    return robot.emulator
