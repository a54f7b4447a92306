"""Test helpers for code built on the SDK: Hypothesis strategies derived from the spec.

Needs hypothesis (the SDK's ``dev`` extra); ``import host_sdk`` alone never imports it.

    from hypothesis import given
    from host_sdk import messages
    from host_sdk.testing import strategies as rls

    @given(rls.message(messages.SetWheelSpeeds))
    def test_my_controller_accepts_any_setpoint(msg: messages.SetWheelSpeeds) -> None:
        ...

See `host_sdk.testing.strategies` for `message`, `messages`, `frames`, `streams` and more.
"""

from host_sdk.testing import strategies
from host_sdk.testing.strategies import Stream, field_values, frames, message, messages, seqs, streams

__all__ = ["Stream", "field_values", "frames", "message", "messages", "seqs", "strategies", "streams"]
