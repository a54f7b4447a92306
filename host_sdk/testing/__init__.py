"""Test helpers for code built on the SDK: Hypothesis strategies derived from the spec, and the
pytest plugin (fixtures `robot`, `emulator`, `roverlink_options`; host_sdk.testing.pytest_plugin).

The strategies need hypothesis (the SDK's ``dev`` extra); ``import host_sdk`` never imports it,
and neither does the pytest plugin, so installing the SDK never breaks a pytest run without it.

    from hypothesis import given
    from host_sdk import messages
    from host_sdk.testing import strategies as rls

    @given(rls.message(messages.SetWheelSpeeds))
    def test_my_controller_accepts_any_setpoint(msg: messages.SetWheelSpeeds) -> None:
        ...

See `host_sdk.testing.strategies` for `message`, `messages`, `frames`, `streams` and more.
"""

from __future__ import annotations

import importlib
from typing import Any

__all__ = ["Stream", "field_values", "frames", "message", "messages", "seqs", "strategies", "streams"]


def __getattr__(name: str) -> Any:
    # Lazy: the strategies module imports hypothesis.
    if name == "strategies":
        return importlib.import_module("host_sdk.testing.strategies")
    if name in __all__:
        return getattr(importlib.import_module("host_sdk.testing.strategies"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
