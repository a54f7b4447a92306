"""`make` for the tests' native builds, one at a time per build folder.

pytest-xdist runs tests in several processes; two of them running `make` into the same folder at
once would read each other's half-written objects. A lock file beside the build folder makes the
second wait for the first, whose up-to-date build then makes its own `make` a no-op.
"""

from __future__ import annotations

import fcntl
import hashlib
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LOCKS = ROOT / "build" / ".make-locks"
MAKE_TIMEOUT_S = 600


def make(
    directory: Path, *targets: str, build: Path | None = None, quiet: bool = True
) -> subprocess.CompletedProcess[str]:
    """`make -C directory targets [BUILD=build]` under the build folder's lock; the result, whatever it is."""
    target = str((build or directory).resolve())
    lock_path = LOCKS / f"{Path(target).name}-{hashlib.sha256(target.encode()).hexdigest()[:8]}.lock"
    LOCKS.mkdir(parents=True, exist_ok=True)
    command = ["make", "-C", str(directory), *targets, *([f"BUILD={build}"] if build else [])]
    with lock_path.open("w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        return subprocess.run(command, capture_output=quiet, text=True, timeout=MAKE_TIMEOUT_S, check=False)


def require_make(directory: Path, *targets: str, build: Path | None = None) -> subprocess.CompletedProcess[str]:
    """`make` that fails the test with make's output when it fails."""
    result = make(directory, *targets, build=build)
    if result.returncode != 0:
        shown = " ".join(targets) or "(default)"
        pytest.fail(
            f"make {shown} in {directory} failed (exit {result.returncode}):\n{result.stdout}\n{result.stderr}",
            pytrace=False,
        )
    return result
