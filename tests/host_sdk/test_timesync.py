"""Clock sync recovers offset and drift, ignores queueing outliers, and unwraps u32 MCU time."""

from __future__ import annotations

import random

import pytest
from hypothesis import given
from hypothesis import strategies as st

from host_sdk.timesync import ClockSync, Unwrapper


def test_unwrapper_is_monotonic_across_wraps() -> None:
    u = Unwrapper()
    raw = [2**32 - 30, 2**32 - 10, 5, 2**31, 2**32 - 5, 7, 3]
    out = [u(r) for r in raw]
    assert out == [2**32 - 30, 2**32 - 10, 2**32 + 5, 2**32 + 2**31, 2**33 - 5, 2**33 + 7, 2**33 + 3]


@given(st.floats(-50_000, 50_000), st.floats(-200, 200), st.integers(0, 2**32 - 1))
def test_offset_and_drift_are_recovered(offset_ms: float, drift_ppm: float, start_raw: int) -> None:
    rng = random.Random(1)
    sync = ClockSync(window=32)
    host = 100.0
    for _ in range(32):
        send = host
        one_way = 0.0004 + rng.random() * 0.0002  # symmetric legs: the midpoint is unbiased
        mcu_true = offset_ms * 1e3 + (send + one_way) * 1e6 * (1 + drift_ppm * 1e-6)
        sync.add(send, send + 2 * one_way, (start_raw + int(mcu_true)) % 2**32)
        host += 0.5
    assert sync.drift_ppm == pytest.approx(drift_ppm, abs=2.0)
    # Mapping an MCU stamp back to the host clock is right within the legs' jitter.
    mcu_now = sync.unwrap((start_raw + int(offset_ms * 1e3 + host * 1e6 * (1 + drift_ppm * 1e-6))) % 2**32)
    assert sync.to_host_s(mcu_now) == pytest.approx(host, abs=3e-4)


def test_slow_round_trips_do_not_skew_the_estimate() -> None:
    sync = ClockSync(window=16)
    for k in range(16):
        send = k * 1.0
        # Every fourth exchange sat 30 ms in a queue on the way back: its midpoint is 15 ms late.
        recv = send + (0.030 if k % 4 == 3 else 0.001)
        sync.add(send, recv, int((send + 0.0005) * 1e6) + 5_000_000)
    assert sync.offset_us(10.0) == pytest.approx(5_000_000, abs=100)
    assert sync.rtt_s == pytest.approx(0.001)


def test_reset_forgets_the_old_boot() -> None:
    sync = ClockSync()
    sync.add(0.0, 0.001, 123_456)
    sync.reset()
    assert not sync.synced and sync.drift_ppm == 0.0


def test_receive_before_send_is_refused() -> None:
    with pytest.raises(ValueError, match="before host_send_s"):
        ClockSync().add(1.0, 0.5, 0)
