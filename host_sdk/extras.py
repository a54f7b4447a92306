"""Optional dependencies, imported only when a feature needs them (the SDK's and the tools').

`import host_sdk` and `roverlink --help` stay small on a Raspberry Pi: Textual, matplotlib and
foxglove-sdk are extras (`pip install 'roverlink[tui]'`, `[plot]`, `[foxglove]`, or `[tools]`
for all three), and a command that needs a missing one says which to install.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from host_sdk.errors import RoverLinkError


class MissingDependencyError(RoverLinkError, ImportError):
    """A feature needs an optional dependency that is not installed; names the extra to install."""

    def __init__(self, module: str, extra: str, what: str) -> None:
        self.module = module
        self.extra = extra
        super().__init__(
            f"{what} needs the Python package {module!r}, which is not installed: "
            f"pip install 'roverlink[{extra}]' (or 'roverlink[tools]' for every tool)"
        )


def require(module: str, extra: str, what: str) -> ModuleType:
    """`importlib.import_module(module)`, or MissingDependencyError naming the extra."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        if exc.name is not None and not module.startswith(exc.name.split(".")[0]):
            raise  # the package is there but one of its own imports failed: show that
        raise MissingDependencyError(module, extra, what) from exc
