"""A web console for a robot program: the robot's camera, scan, pose and status in a browser, and
the controls to choose a target, follow it, drive, arm and stop (docs/console.md).

    sup = Supervisor.connect("/dev/ttyACM0", profile="picar", clamp=True)   # rides through the robot's failures
    console = Console(sup, geometry, host="0.0.0.0")            # off loopback: a token is made
    print(console.start())                                      # the URL to open, token included
    loop = ControlLoop(sup, console.pilot, lidar=lidar, camera=camera)   # arming is the page's
    with loop:
        while True:
            loop.step()
            loop.wait()

The server runs in a thread of its own (aiohttp: the `console` extra); the program's loop feeds it
through a `Hub` and drives what `console.pilot` decides.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from host_sdk.console.access import Access, is_loopback
from host_sdk.console.hub import Hub

if TYPE_CHECKING:
    from host_sdk.console.console import Console
    from host_sdk.console.pilot import ConsolePilot
    from host_sdk.console.server import ConsoleServer

__all__ = ["Access", "Console", "ConsolePilot", "ConsoleServer", "Hub", "is_loopback"]

_LAZY = {"Console": "console", "ConsolePilot": "pilot", "ConsoleServer": "server"}


def __getattr__(name: str) -> Any:
    # The console, its pilot and server pull in the autonomy stack: loaded when asked for, so that a
    # command needing only `is_loopback` stays quick to start.
    if name in _LAZY:
        import importlib  # noqa: PLC0415

        return getattr(importlib.import_module(f"host_sdk.console.{_LAZY[name]}"), name)
    raise AttributeError(f"module 'host_sdk.console' has no attribute {name!r}")
