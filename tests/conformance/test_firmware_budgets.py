"""The firmware budgets of docs/budgets.md measured on the real binaries in simavr (benchmarks/firmware.py).

`pytest -s` prints the figures and where the decode and dispatch cycles go. About 10 s for the
three examples.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import firmware as bench

from protocol.generated.profiles import PROFILES

EXAMPLES = sorted(p.example for p in PROFILES.values())


@pytest.fixture(scope="module")
def figures() -> dict[str, bench.Figures]:
    out = {p.example: bench.measure(p.example, name) for name, p in sorted(PROFILES.items())}
    for f in out.values():
        print("\n  " + bench.report(f))
    for f in out.values():
        print("\n" + bench.breakdown(f))
    return out


@pytest.mark.parametrize("example", EXAMPLES)
def test_control_loop_and_byte_latency_within_budget(figures: dict[str, bench.Figures], example: str) -> None:
    f = figures[example]
    assert f.control_cpu_share <= bench.CONTROL_SHARE_BUDGET
    assert f.worst_rx_isr_latency_cycles <= 2 * bench.CYCLES_PER_BYTE
    assert f.realtime_ratio >= 1.0, "the firmware-in-the-loop must run at least as fast as real time"


@pytest.mark.parametrize("example", EXAMPLES)
def test_no_receive_overrun_with_frames_back_to_back(figures: dict[str, bench.Figures], example: str) -> None:
    f = figures[example]
    assert f.rx_bytes > 0
    assert f.rx_overruns == 0


@pytest.mark.xfail(
    strict=True,
    reason="measured 2,518 (AckermannPiCar) to 2,543 (the Mega examples) AVR cycles to decode and dispatch a "
    "SET_PID frame (17-byte payload, 23 bytes on the wire, at 115200 baud mostly one byte per poll() call), budget 1500, plus "
    "about 1,000 of handling and reply reported apart: reading the bytes (poll's loop, one virtual read() per byte) "
    "about 420, the frame decoder about 745 (COBS undone byte by byte about 675, the frame checks about 70), "
    "CRC-16 about 470, unpacking and the range checks about 370, the session rules and dispatch about 520; "
    "`pytest -s` prints the breakdown (benchmarks/firmware.py)",
)
@pytest.mark.parametrize("example", EXAMPLES)
def test_command_frame_decode_and_dispatch_within_budget(figures: dict[str, bench.Figures], example: str) -> None:
    assert figures[example].decode_dispatch_cycles_per_set_pid_frame <= bench.FRAME_CYCLES_BUDGET


@pytest.mark.parametrize("example", EXAMPLES)
def test_longest_poll_call_is_bounded_by_the_loop_pass_around_it(
    figures: dict[str, bench.Figures], example: str
) -> None:
    """The longest poll() (handling left out) does more than an idle one and fits inside the
    longest main-loop pass, which contains it: a harness that lost a call's end, or counted the
    handlers twice, breaks one of the two."""
    f = figures[example]
    assert f.poll_idle_call_cycles < f.longest_set_pid_poll_cycles < f.worst_loop_pass_cycles


@pytest.mark.parametrize("example", EXAMPLES)
def test_handling_and_reply_are_kept_apart_from_decode_and_dispatch(
    figures: dict[str, bench.Figures], example: str
) -> None:
    """The ACK's sending and the App's handler run inside the harness's handler boundaries, and
    nothing of them leaks into the decode-and-dispatch figure (or the boundaries matched nothing)."""
    functions = figures[example].set_pid_breakdown["function"]
    for name in ("roverlink::Link::send_payload", "roverlink::Firmware::set_pid"):
        assert functions.get(f"{name} (handling)", 0) > 0, f"{name} not seen as handling: {list(functions)}"
        assert name not in functions, f"{name} counted as decode and dispatch"
    assert figures[example].handling_cycles_per_set_pid_frame > 0
