"""Real-time scheduling for a robot program's process: every thread under SCHED_FIFO.

    from host_sdk.hostinfo import realtime
    realtime.make_realtime(20)   # this process's threads now, and (inherited) those it starts later

On a host whose cores are busy with other work, a normal-priority thread waking for a board tick
waits behind that work: on a 2-core machine with two busy loops a lone thread waking every 10 ms
was 12 ms late one time in a thousand (benchmarks/results/ros2.md). Raising only the SDK's I/O
thread does not help for long: Python's threads share one GIL, and the thread holding it can be put
behind the other work while the raised one waits for it. So every thread of the process is
raised, as ros2_control raises its control loop, and the threads it starts later inherit the policy.

Linux only. It needs CAP_SYS_NICE (root has it) or an rtprio limit at least `priority`
(`ulimit -r`, `@realtime - rtprio 50` in /etc/security/limits.conf); otherwise RealtimeError says
so. A program under SCHED_FIFO that spins takes its cores from everything else but the kernel's
real-time throttling share (95 % by default); RoverLink's threads block between frames.
"""

from __future__ import annotations

import os
import threading
from pathlib import Path

from host_sdk.errors import CommandRangeError, RealtimeError

TASKS = Path("/proc/self/task")
MAX_PRIORITY = 99
"""SCHED_FIFO's highest on Linux; a robot program should stay well below the kernel's own threads' (50)."""


def make_realtime(priority: int) -> int:
    """Every thread of this process under SCHED_FIFO at `priority` (1..99); the number of threads
    changed. RealtimeError (a PermissionError) when the system does not allow it."""
    if isinstance(priority, bool) or not isinstance(priority, int) or not 1 <= priority <= MAX_PRIORITY:
        raise CommandRangeError("priority", priority, f"1..{MAX_PRIORITY} (SCHED_FIFO)")
    if not hasattr(os, "sched_setscheduler") or not TASKS.is_dir():
        raise RealtimeError(f"SCHED_FIFO {priority}: real-time scheduling needs Linux")
    changed = 0
    for task in sorted(TASKS.iterdir()):
        try:
            os.sched_setscheduler(int(task.name), os.SCHED_FIFO, os.sched_param(priority))
        except ProcessLookupError:  # the thread ended meanwhile
            continue
        except PermissionError as exc:
            import resource  # noqa: PLC0415 (Unix only, as this path is)

            limit = resource.getrlimit(resource.RLIMIT_RTPRIO)[0]
            raise RealtimeError(
                f"SCHED_FIFO {priority}: not permitted (this user's rtprio limit is {limit}): raise it "
                f"(`ulimit -r {priority}`, or `@realtime - rtprio {priority}` in /etc/security/limits.conf "
                "and the user in group realtime) or give the program CAP_SYS_NICE"
            ) from exc
        changed += 1
    return changed


def allowed(priority: int) -> bool:
    """Whether this process may put its threads under SCHED_FIFO at `priority`: tried on a thread of
    its own, which then ends (a container may refuse it even to root: no CAP_SYS_NICE, or no
    real-time share in its cgroup)."""
    if not hasattr(os, "sched_setscheduler"):
        return False
    result: list[bool] = []

    def attempt() -> None:
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
        except OSError:
            result.append(False)
            return
        result.append(True)
        os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))

    probe = threading.Thread(target=attempt, name="realtime-probe")
    probe.start()
    probe.join()
    return result == [True]


def policy_of(tid: int) -> tuple[int, int]:
    """A thread's scheduling policy and priority (os.SCHED_*), for a check or a log line."""
    return os.sched_getscheduler(tid), os.sched_getparam(tid).sched_priority
