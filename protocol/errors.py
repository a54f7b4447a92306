"""The root of RoverLink's one exception tree, and the codec's errors.

Every error any RoverLink package raises is a `RoverLinkError`; each leaf also inherits the
built-in it behaves like, so `except ValueError` in user code keeps working. The codec's errors
live here with the codec; the SDK (host_sdk.errors) and the emulator add their leaves below the
same root.
"""

from __future__ import annotations


class RoverLinkError(Exception):
    """Root of every error RoverLink raises (codec, SDK, emulator, tools)."""


class CodecError(RoverLinkError):
    """A message could not be turned into bytes, or bytes into a message."""


class EncodeError(CodecError, ValueError):
    """A message field is outside its type or range; nothing was encoded.

    Attributes name the message, the field, the offending value and what is allowed.
    """

    def __init__(self, message: str, field: str, value: object, allowed: str) -> None:
        self.message = message
        self.field = field
        self.value = value
        self.allowed = allowed
        super().__init__(f"{message}.{field} = {value!r} is not allowed: {allowed}")


class DecodeError(CodecError, ValueError):
    """A payload does not decode to its message (length or value outside the spec)."""

    def __init__(self, message: str, problem: str) -> None:
        self.message = message
        self.problem = problem
        super().__init__(f"{message}: {problem}")


class ArgumentError(RoverLinkError, ValueError):
    """A bad argument to a public call: outside its range, NaN, infinite, or of the wrong kind.

    Attributes: `argument` (its name), `value`, `allowed` (what would be accepted, in words).
    """

    def __init__(self, argument: str, value: object, allowed: str, hint: str = "") -> None:
        self.argument = argument
        self.value = value
        self.allowed = allowed
        shown = repr(value)
        if len(shown) > 80:
            shown = shown[:77] + "..."
        super().__init__(f"{argument} = {shown} is not allowed: {allowed}" + (f"; {hint}" if hint else ""))


class ArgumentTypeError(ArgumentError, TypeError):
    """A bad argument of the wrong type (a str where a number goes, a bool where a count goes...)."""
