"""Test helpers for code built on the SDK: an emulated robot per test, drive commands as values,
Hypothesis strategies derived from the spec, and the pytest plugin (fixtures `roverlink_robot`,
`roverlink_emulator`, `roverlink_options`; host_sdk.testing.pytest_plugin). docs/sdk.md, "Testing your robot code".

The strategies need hypothesis (the SDK's ``dev`` extra); ``import host_sdk`` never imports it,
and neither do the pytest plugin, `emulated_robot` and the commands, so installing the SDK never
breaks a pytest run without it.

    from hypothesis import given
    from host_sdk import messages
    from host_sdk.testing import emulated_robot, run_steps, strategies as rls

    @given(rls.message(messages.SetWheelSpeeds))
    def test_my_controller_accepts_any_setpoint(msg: messages.SetWheelSpeeds) -> None:
        ...

    @given(rls.command_sequences("diffdrive-tb6612"))
    def test_my_code_survives_any_drive(steps: list[rls.Step]) -> None:
        with emulated_robot(armed=True) as robot:     # a fresh robot per example
            run_steps(robot, steps)

See `host_sdk.testing.strategies` for `message`, `messages`, `frames`, `streams`,
`drive_commands`, `command_sequences` and more.
"""

from __future__ import annotations

import importlib
from typing import Any

from host_sdk.testing.commands import AckermannCommand, DriveCommand, Step, Twist, WheelSpeeds, run_steps
from host_sdk.testing.emulated_robot import emulated_robot, emulator_url

__all__ = [
    "AckermannCommand",
    "DriveCommand",
    "Step",
    "Twist",
    "WheelSpeeds",
    "emulated_robot",
    "emulator_url",
    "run_steps",
    "strategies",
]
_LAZY = frozenset("Stream command_sequences drive_commands field_values frames message messages seqs streams".split())
"""Also here, loaded on first use: the names of `host_sdk.testing.strategies`."""


def __getattr__(name: str) -> Any:
    # Lazy: the strategies module imports hypothesis.
    if name == "strategies":
        return importlib.import_module("host_sdk.testing.strategies")
    if name in _LAZY:
        return getattr(importlib.import_module("host_sdk.testing.strategies"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
