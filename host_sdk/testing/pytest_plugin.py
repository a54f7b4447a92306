"""pytest fixtures for testing robot code against the emulator (registered as the `roverlink` plugin).

    def test_drives_forward(roverlink_robot, roverlink_emulator):
        roverlink_robot.arm()
        for _ in range(50):
            roverlink_robot.drive(0.3, 0.0)
            roverlink_robot.sleep(0.02)   # virtual time: instant, deterministic
        assert roverlink_emulator.truth.plant.x_m > 0.2

Fixtures (every name starts with `roverlink_`, so none shadows or is shadowed by a project's own
`robot` or `emulator` fixture; the plugin is registered whenever RoverLink is installed):

- `roverlink_robot`: a `host_sdk.Robot` connected to an in-process emulator on a virtual clock, ready
  (disarmed unless `armed=True`). Time passes only while it waits: `robot.sleep(s)`,
  `robot.wait_feedback()`, requests. No threads, so runs are reproducible from the seed.
- `roverlink_emulator`: the `emulator.Emulator` behind it, typed as `host_sdk.emulated.EmulatorHandle`:
  `.truth` (ground truth: pose, wheel speeds, firmware state), fault injection (`cut_link()`,
  `reset_mcu()`, `set_drop_rate()`, ...). Calling `roverlink_emulator.advance(s)` directly runs the robot
  while the host is frozen (the watchdog acts).
- `roverlink_options`: the dict the fixtures are built from; override it in a conftest.py, or set
  fields per test with `@pytest.mark.roverlink(profile="picar", seed=3, faults="drop=1e-3",
  mode="lockstep", armed=True, watchdog_s=0.5, imu="jy901", ...)`: the options of
  `host_sdk.testing.emulated_robot` (an unknown key fails the test, naming it and listing them).

In a Hypothesis ``@given`` test use `emulated_robot(...)` in the body instead of these fixtures
(one robot per example; docs/sdk.md, "Property tests").
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from host_sdk.emulated import EmulatorHandle
from host_sdk.robot import Robot
from host_sdk.testing.emulated_robot import DEFAULTS, OPTIONS, check_options, emulated_robot, emulator_url

__all__ = ["DEFAULTS", "emulator_url", "roverlink_emulator", "roverlink_options", "roverlink_robot"]


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        f"roverlink(**options): configure the emulated `roverlink_robot` and `roverlink_emulator` fixtures "
        f"of the roverlink plugin; options: {', '.join(OPTIONS)}",
    )


@pytest.fixture
def roverlink_options(request: pytest.FixtureRequest) -> dict[str, Any]:
    """Options of the emulated robot: DEFAULTS, updated by a @pytest.mark.roverlink(...) on the test."""
    options = dict(DEFAULTS)
    for marker in reversed(list(request.node.iter_markers("roverlink"))):
        if marker.args:
            pytest.fail(f"@pytest.mark.roverlink takes keywords only, not {marker.args!r}", pytrace=False)
        problem = None
        try:
            check_options(marker.kwargs, "@pytest.mark.roverlink")
        except TypeError as exc:
            problem = str(exc)
        if problem is not None:  # failed outside the handler: one message, not two chained
            pytest.fail(problem, pytrace=False)
        options.update(marker.kwargs)
    return options


@pytest.fixture
def roverlink_robot(roverlink_options: dict[str, Any]) -> Iterator[Robot]:
    """A Robot on an in-process emulator with a virtual clock, connected and ready."""
    with emulated_robot(**roverlink_options) as bot:
        yield bot


@pytest.fixture
def roverlink_emulator(roverlink_robot: Robot) -> EmulatorHandle:
    """The emulator.Emulator behind `roverlink_robot`: ground truth (`.truth`) and fault injection."""
    emu = roverlink_robot.emulator
    assert emu is not None, "the roverlink plugin's robot is always an emu:// one"
    return emu
