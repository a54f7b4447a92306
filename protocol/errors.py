"""The root of RoverLink's one exception tree, and the codec's errors.

Every error any RoverLink package raises is a `RoverLinkError`; each leaf also inherits the
built-in it behaves like, so `except ValueError` in user code keeps working. The codec's errors
live here with the codec; the SDK (host_sdk.errors) and the emulator add their leaves below the
same root.
"""

from __future__ import annotations

import contextlib
import importlib
import io
import sys
from types import ModuleType

from protocol import numpy_abi


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


TOOLS_EXTRAS = ("tui", "plot", "foxglove")
"""The extras the `tools` extra gathers (pyproject.toml; tests/system/test_readme.py checks)."""


class MissingDependencyError(RoverLinkError, ImportError):
    """A feature needs an optional dependency that is not installed; names the extra to install.

    It lives at the root so the SDK and the emulator raise the same error (`import_optional`)
    and a tool reports both in one line."""

    def __init__(self, module: str, extra: str, what: str) -> None:
        self.module = module
        self.extra = extra
        every_tool = " (or 'roverlink[tools]' for every tool)" if extra in TOOLS_EXTRAS else ""
        super().__init__(
            f"{what} needs the Python package {module!r}, which is not installed: "
            f"pip install 'roverlink[{extra}]'{every_tool}"
        )


class NumpyAbiError(MissingDependencyError):
    """A compiled module (OpenCV, picamera2, simplejpeg) is installed but was built against another
    numpy than the one imported: names the module, the numpy and the fix (protocol.numpy_abi)."""

    def __init__(self, module: str, cause: BaseException) -> None:
        self.module = module
        self.extra = ""
        super(MissingDependencyError, self).__init__(numpy_abi.describe(module, cause))


def import_compiled(module: str) -> ModuleType:
    """`importlib.import_module(module)`, or NumpyAbiError when numpy refuses it. numpy's own
    several-line banner for that case is kept off stderr: the error says it in one line."""
    banner = io.StringIO()
    try:
        with contextlib.redirect_stderr(banner):
            loaded = importlib.import_module(module)
    except (ImportError, ValueError, RuntimeError, AttributeError) as exc:
        if numpy_abi.is_numpy_abi_break(exc):
            raise NumpyAbiError(module, exc) from exc
        sys.stderr.write(banner.getvalue())
        raise
    sys.stderr.write(banner.getvalue())
    return loaded


def import_optional(module: str, extra: str, what: str) -> ModuleType:
    """`importlib.import_module(module)`, or MissingDependencyError naming the extra (NumpyAbiError
    when it is there but built for another numpy)."""
    try:
        return import_compiled(module)
    except NumpyAbiError:
        raise
    except ImportError as exc:
        if exc.name is not None and not module.startswith(exc.name.split(".")[0]):
            raise  # the package is there but one of its own imports failed: show that
        raise MissingDependencyError(module, extra, what) from exc
