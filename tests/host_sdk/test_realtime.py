"""host_sdk.hostinfo.realtime: every thread of the process under SCHED_FIFO, those started later
too; a system that does not allow it is told with the limit to raise. Each case runs in a process
of its own, so the test run itself is never real-time."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from host_sdk import CommandRangeError
from host_sdk.hostinfo.realtime import allowed, make_realtime
from tests.support.realtime import without_realtime

CHILD = """
import json, os, threading
from host_sdk.hostinfo.realtime import make_realtime, policy_of
from host_sdk import RealtimeError
gate = threading.Event()
before = threading.Thread(target=gate.wait)
before.start()
try:
    changed = make_realtime(3)
except RealtimeError as exc:
    gate.set()
    print(json.dumps({"error": str(exc), "permission": isinstance(exc, PermissionError)}))
    raise SystemExit(0)
seen = {}
def later():
    seen["later"] = policy_of(threading.get_native_id())
after = threading.Thread(target=later)
after.start(); after.join()
seen["before"] = policy_of(before.native_id)
seen["main"] = policy_of(threading.get_native_id())
gate.set(); before.join()
print(json.dumps({"changed": changed, **seen}))
"""


def _child(*prefix: str) -> dict[str, object]:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    command = [*prefix, sys.executable, "-c", CHILD]
    out = subprocess.run(command, capture_output=True, text=True, timeout=60, env=env, check=False)
    assert out.returncode == 0, out.stderr
    result: dict[str, object] = json.loads(out.stdout)
    return result


def test_every_thread_and_those_started_later_run_under_sched_fifo() -> None:
    if not allowed(3):
        pytest.skip("this process may not use SCHED_FIFO (no CAP_SYS_NICE or rtprio limit, or a container's cgroup)")
    seen = _child()
    fifo = [os.SCHED_FIFO, 3]
    assert seen["before"] == fifo and seen["main"] == fifo and seen["later"] == fifo, seen
    assert isinstance(seen["changed"], int) and seen["changed"] >= 2


def test_a_system_that_does_not_allow_it_is_told_which_limit_to_raise() -> None:
    # Without CAP_SYS_NICE (even as root) and with an rtprio limit of 0, as a default user's.
    seen = _child(*without_realtime())
    assert seen["permission"] is True
    assert "SCHED_FIFO 3: not permitted (this user's rtprio limit is 0): raise it (`ulimit -r 3`" in str(seen["error"])


@pytest.mark.parametrize("priority", [0, 100, True])
def test_a_priority_out_of_range_is_refused(priority: int) -> None:
    with pytest.raises(CommandRangeError, match=r"1\.\.99"):
        make_realtime(priority)
