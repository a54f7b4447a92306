"""An emulated board in another process, on a pseudo-terminal (`roverlink emulate`).

The Textual tests need it: Textual's pilot waits until the process is idle, and an in-process
emulator on the wall clock keeps the test's own process busy.
"""

from __future__ import annotations

import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager


@contextmanager
def pty_board(profile: str) -> Iterator[str]:
    """Yields the pty's path; the emulator stops when the block ends."""
    code = "import sys; from roverlink.cli import main; sys.exit(main())"
    proc = subprocess.Popen(
        [sys.executable, "-c", code, "emulate", "--quiet", "--profile", profile],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    try:
        assert proc.stdout is not None
        path = proc.stdout.readline().strip()
        assert path.startswith("/dev/"), f"roverlink emulate printed {path!r}"
        yield path
    finally:
        proc.terminate()
        proc.wait(timeout=10)
        if proc.stdout is not None:
            proc.stdout.close()


async def until(predicate: Callable[[], bool], pilot: object, timeout_s: float = 10.0) -> bool:
    """Let a Textual app run (its pilot pausing) until `predicate()`, at most `timeout_s`."""
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            return False
        await pilot.pause(0.05)  # type: ignore[attr-defined]
    return True
