"""One exception tree for the whole SDK.

Every error is a `RoverLinkError`; each leaf also inherits the built-in it behaves like, so
`except ValueError` or `except TimeoutError` in user code keeps working.
"""

from __future__ import annotations


class RoverLinkError(Exception):
    """Root of every error the SDK raises."""


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
