"""A process that may not use real-time scheduling, for the tests of a refusal."""

from __future__ import annotations

import shutil
import subprocess

import pytest

NO_RT = ("setpriv", "--bounding-set", "-sys_nice", "--inh-caps", "-sys_nice", "prlimit", "--rtprio=0")
"""A process without CAP_SYS_NICE (even as root) and with a default user's rtprio limit of 0."""


def without_realtime() -> tuple[str, ...]:
    """NO_RT, or a skip where this system cannot run it (util-linux missing, or dropping a
    capability not allowed here)."""
    if shutil.which("setpriv") is None or shutil.which("prlimit") is None:
        pytest.skip("needs util-linux's setpriv and prlimit")
    if subprocess.run([*NO_RT, "true"], capture_output=True, check=False).returncode != 0:
        pytest.skip("setpriv cannot drop CAP_SYS_NICE here (no CAP_SETPCAP)")
    return NO_RT
