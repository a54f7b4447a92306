"""The firmware budgets of docs/budgets.md measured on the real binaries in simavr (benchmarks/firmware.py).

`pytest -s` prints the figures and where the decode and dispatch cycles go. About 10 s for the
three examples.
"""

from __future__ import annotations

import dataclasses

import firmware as bench  # benchmarks/firmware.py (benchmarks/ is on pytest's pythonpath)
import line_use
import pytest

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
    # How fast the simulation runs against the wall clock is the benchmark's to print
    # (f.realtime_ratio), not a test's to assert: it measures the host machine, not the firmware.


@pytest.mark.parametrize("example", EXAMPLES)
def test_no_receive_overrun_with_frames_back_to_back(figures: dict[str, bench.Figures], example: str) -> None:
    f = figures[example]
    assert f.rx_bytes > 0
    assert f.rx_overruns == 0


@pytest.mark.parametrize("example", EXAMPLES)
def test_frame_decoder_cost_per_byte_within_budget(figures: dict[str, bench.Figures], example: str) -> None:
    """<= 86 cycles per byte: at least 2.5x fewer than SerialTransfer's parse() (214.8)."""
    f = figures[example]
    assert 0 < f.decoder_cycles_per_byte <= bench.DECODER_CYCLES_PER_BYTE_BUDGET
    assert bench.SERIALTRANSFER_CYCLES_PER_BYTE / f.decoder_cycles_per_byte >= bench.DECODER_RATIO_BUDGET


@pytest.mark.parametrize("example", EXAMPLES)
def test_read_decode_and_dispatch_per_byte_within_budget(figures: dict[str, bench.Figures], example: str) -> None:
    f = figures[example]
    assert bench.frame_cycles_per_byte(f) <= bench.FRAME_CYCLES_PER_BYTE_BUDGET
    # The decoder is part of the whole: a harness or filter that lost it would pass the gate above.
    assert f.decoder_cycles_per_byte < bench.frame_cycles_per_byte(f)


@pytest.mark.parametrize("example", EXAMPLES)
def test_longest_poll_call_delays_a_control_tick_within_budget(figures: dict[str, bench.Figures], example: str) -> None:
    """A control tick is checked between poll() calls: the longest call is the most a tick waits
    (5 % of the period; docs/budgets.md says why). Entry to return includes what the profile's
    figure leaves out (handling, reply, interrupts), so it is the larger of the two."""
    f = figures[example]
    assert f.longest_set_pid_poll_cycles < f.longest_poll_span_cycles <= bench.POLL_SPAN_BUDGET_CYCLES


@pytest.mark.parametrize("example", EXAMPLES)
def test_line_use_at_100_hz_within_budget(figures: dict[str, bench.Figures], example: str) -> None:
    line = figures[example].line
    assert line_use.problems(line) == []
    assert 0 < line.host_to_mcu < line.mcu_to_host <= line_use.LINE_SHARE_BUDGET


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


def test_the_benchmark_names_the_budget_that_fails(figures: dict[str, bench.Figures]) -> None:
    """benchmarks/firmware.py exits non-zero with one line per broken budget, naming it."""
    f = figures[EXAMPLES[0]]
    assert bench.problems(f) == []
    over = {
        "frame decoder": {"decoder_cycles_per_byte": bench.DECODER_CYCLES_PER_BYTE_BUDGET + 1.0},
        "read, decode and dispatch": {
            "decode_dispatch_cycles_per_set_pid_frame": (bench.FRAME_CYCLES_PER_BYTE_BUDGET + 1) * f.set_pid_frame_bytes
        },
        "longest poll()": {"longest_poll_span_cycles": bench.POLL_SPAN_BUDGET_CYCLES + 1},
        "MCU-to-host": {"line": dataclasses.replace(f.line, mcu_to_host=line_use.LINE_SHARE_BUDGET + 0.01)},
    }
    for name, change in over.items():
        found = bench.problems(dataclasses.replace(f, **change))  # type: ignore[arg-type]
        assert len(found) == 1 and name in found[0], (name, found)
