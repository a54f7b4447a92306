"""Optional dependencies, imported only when a feature needs them (the SDK's and the tools').

`import host_sdk` and `roverlink --help` stay small on a Raspberry Pi: OpenCV, Textual, matplotlib
and foxglove-sdk are extras (`pip install 'roverlink[vision]'`, `[tui]`, `[plot]`, `[foxglove]`,
or `[tools]` for the tools' three), and a command that needs a missing one says which to install.
The error and the import live in protocol.errors, so the emulator raises the same one; a module
that is there but built for another numpy than the one found (apt's OpenCV or picamera2 under a
pip numpy) is a NumpyAbiError, one line naming the module, the numpy and the fix.
"""

from __future__ import annotations

from protocol.errors import MissingDependencyError, NumpyAbiError, import_compiled
from protocol.errors import import_optional as require

__all__ = ["MissingDependencyError", "NumpyAbiError", "import_compiled", "require"]
