"""A lockstep robot that is never armed: the bridge publishes odom and the odom -> base_link
transform at `odom_rate` from the first second, as SLAM needs them before anything drives (a
lockstep board streams FEEDBACK while it is not armed), and a cut link is a silence in diagnostics.

Rates are read from the header stamps (the MCU's clock), so a busy test machine does not make them
flaky; a stamp-based window is the first second after the first message.
"""

from __future__ import annotations

import itertools
import statistics
import time
import uuid
from pathlib import Path
from typing import Any

import pytest
from ros_env import require_ros

require_ros()

from bridge_harness import BridgeProcess, Probe, logged, stamp_s, values  # noqa: E402
from std_srvs.srv import SetBool  # noqa: E402

ODOM_RATE = 25
"""Not the board's configured 50 Hz: the rate must be the session's, the node's odom_rate."""


def first_second(stamps: list[float]) -> list[float]:
    return [s for s in stamps if s < stamps[0] + 1.0]


def at_rate(stamps: list[float], what: str) -> None:
    gaps = [b - a for a, b in itertools.pairwise(stamps)]
    assert all(g > 0 for g in gaps), f"{what} stamps go back"
    assert statistics.median(gaps) == pytest.approx(1 / ODOM_RATE, rel=0.2), f"{what} is not at {ODOM_RATE} Hz"
    assert len(first_second(stamps)) == pytest.approx(ODOM_RATE, rel=0.2), (
        f"{what}: not {ODOM_RATE} in its first second"
    )


def test_a_disarmed_lockstep_robot_publishes_odom_and_tf_at_odom_rate(ros: None, tmp_path: Path) -> None:
    from tf2_msgs.msg import TFMessage

    ns = f"/lockstep_idle_{uuid.uuid4().hex[:6]}"
    proc = BridgeProcess(ns, "emu://diffdrive-bts7960?seed=1", tmp_path, params={"odom_rate": ODOM_RATE})
    probe = Probe(ns)
    probe.subscribe("tf", TFMessage, "tf", 100)
    with logged(proc, probe):
        first = probe.wait_for("the first odom", lambda: (probe.since("odom") or [None])[0], 30).at
        probe.wait_for("2 s of odom", lambda: time.monotonic() > first + 2.0, 5)
        odom = [r.msg for r in probe.since("odom")]
        assert all((m.header.frame_id, m.child_frame_id) == ("odom", "base_link") for m in odom)
        at_rate([stamp_s(m.header.stamp) for m in odom], "odom")
        transforms: list[Any] = [
            t
            for r in probe.since("tf")
            for t in r.msg.transforms
            if (t.header.frame_id, t.child_frame_id) == ("odom", "base_link")
        ]
        at_rate([stamp_s(t.header.stamp) for t in transforms], "odom -> base_link")
        # Never armed all along, and FEEDBACK is due: the link is OK, not "no FEEDBACK".
        probe.wait_for("a diagnostics report", lambda: probe.status("link") and probe.status("robot"), 5)
        link, robot = probe.status("link"), probe.status("robot")
        assert values(robot)["state"] == "disarmed" and values(link)["feedback mode"] == "lockstep"
        assert link.level == b"\x00", link.message
        # FEEDBACK is owed while disarmed: a cut link is a silence the diagnostics report.
        assert probe.call("cut_link", SetBool.Request(data=True)).success
        probe.wait_status("link", lambda s: s.message.startswith("no FEEDBACK") and s.level == b"\x02", 4)
        assert probe.call("cut_link", SetBool.Request(data=False)).success
        probe.wait_status("link", lambda s: s.level == b"\x00", 6)
