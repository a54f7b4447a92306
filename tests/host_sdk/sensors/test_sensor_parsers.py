"""Parsers under arbitrary chunking and corruption: same result whatever the chunks, never an
exception on garbage, garbage counted, and whole scans again once the stream is clean."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from sensor_streams import recorded

from host_sdk.sensors import rplidar, wit, ydlidar
from host_sdk.sensors.mjpeg import MjpegParser

LIDARS = {"rplidar-a1": rplidar.RPLidarParser, "ydlidar-f4": ydlidar.YDLidarParser}


def _feed(parser: object, data: bytes, cuts: list[int]) -> list[object]:
    events: list[object] = []
    bounds = sorted({0, len(data), *(c % (len(data) + 1) for c in cuts)})
    for lo, hi in itertools.pairwise(bounds):
        parser.receive_data(data[lo:hi], 1.0)  # type: ignore[attr-defined]
        events.extend(parser.events())  # type: ignore[attr-defined]
    return events


def _scans(events: list[object]) -> list[object]:
    return [e for e in events if hasattr(e, "ranges_m")]


@given(st.sampled_from(sorted(LIDARS)), st.lists(st.integers(0, 10**6), max_size=40))
def test_lidar_chunking_changes_nothing_but_times(model: str, cuts: list[int]) -> None:
    data = recorded("lidar", model)
    whole = _scans(_feed(LIDARS[model](), data, []))
    chunked = _scans(_feed(LIDARS[model](), data, cuts))
    assert len(whole) == len(chunked) >= 2
    for a, b in zip(whole, chunked, strict=True):
        assert np.array_equal(a.angles_rad, b.angles_rad)  # type: ignore[attr-defined]
        assert np.array_equal(a.ranges_m, b.ranges_m, equal_nan=True)  # type: ignore[attr-defined]


@given(
    st.sampled_from(sorted(LIDARS)),
    st.lists(st.tuples(st.integers(0, 10**6), st.binary(min_size=1, max_size=12)), min_size=1, max_size=20),
)
def test_lidar_garbage_is_counted_never_raised_and_scans_resume(model: str, damage: list[tuple[int, bytes]]) -> None:
    data = bytearray(recorded("lidar", model))
    clean_tail = len(data) // 2  # damage only the first half
    for at, junk in damage:
        pos = at % clean_tail
        data[pos : pos + len(junk)] = junk
    parser = LIDARS[model]()
    parser.expect_scan()  # as the driver does when it sends the scan request
    events = _feed(parser, bytes(data), [])
    # A whole clean revolution lies in the undamaged half: the parser found its way back.
    assert len(_scans(events)) >= 1


@given(st.sampled_from(sorted(LIDARS)), st.binary(min_size=1, max_size=300))
def test_lidar_garbage_before_a_clean_stream_is_counted(model: str, junk: bytes) -> None:
    data = recorded("lidar", model)
    parser = LIDARS[model]()
    events = _feed(parser, junk + b"\x00" * 12 + data, [])
    c = parser.counters
    assert c.bytes_discarded + c.framing_errors + c.checksum_errors > 0
    assert len(_scans(events)) >= 2


@given(st.binary(max_size=2000), st.lists(st.integers(0, 2000), max_size=20))
def test_every_parser_survives_pure_noise(noise: bytes, cuts: list[int]) -> None:
    for parser in (rplidar.RPLidarParser(), ydlidar.YDLidarParser(), wit.WitParser(), MjpegParser()):
        bounds = sorted({0, len(noise), *(c % (len(noise) + 1) for c in cuts)})
        for lo, hi in itertools.pairwise(bounds):
            parser.receive_data(noise[lo:hi], 0.0)


@given(st.lists(st.integers(0, 10**6), max_size=30), st.lists(st.integers(0, 10**6), max_size=10))
def test_wit_chunks_and_flips(cuts: list[int], flips: list[int]) -> None:
    data = recorded("imu", "jy901", 0.3)
    clean = wit.WitParser()
    clean.receive_data(data, 1.0)
    reference = [e for e in clean.events() if isinstance(e, wit.ImuSample)]
    assert len(reference) >= 50
    damaged = bytearray(data)
    for f in {f % len(damaged) for f in flips}:
        damaged[f] ^= 0x5A
    parser = wit.WitParser()
    samples = [e for e in _feed(parser, bytes(damaged), cuts) if isinstance(e, wit.ImuSample)]
    if not flips:
        assert samples == reference
    else:
        # Detected (counted), or two flips in one packet cancelled in its sum (then the values differ).
        assert parser.counters.checksum_errors + parser.counters.bytes_discarded > 0 or samples != reference
        assert len(samples) >= len(reference) - 2 * len(flips) - 1


class _ChunkedPort:
    """Hands out one chunk per read, the clock 50 ms on each time (a host loop reading its IMU)."""

    url = "test://imu"

    def __init__(self, chunks: list[bytes]) -> None:
        self.chunks, self.now = chunks, 0.0

    def clock(self) -> float:
        return self.now

    def read(self, timeout_s: float) -> bytes:
        self.now += 0.05
        return self.chunks.pop(0) if self.chunks else b""


def test_imu_samples_read_in_batches_are_spaced_by_the_output_period() -> None:
    """Ten 5 ms periods per read, each read ending inside a period (its group is completed by the
    next read). Every sample gets its own time, one period apart: none stacked on one time (a
    gyro integrating them would lose all but one)."""
    from host_sdk.sensors import Jy901

    def pkt(type_: int) -> bytes:
        body = bytes([0x55, type_]) + bytes(8)
        return body + bytes([sum(body) & 0xFF])

    stream = b"".join(pkt(0x51) + pkt(0x52) for _ in range(60))
    cut = [i * 20 * 11 + 11 for i in range(6)] + [len(stream)]  # after a period's first packet
    imu = Jy901(_ChunkedPort([stream[a:b] for a, b in itertools.pairwise([0, *cut])]))  # type: ignore[arg-type]
    times = [s.t for _ in range(6) for s in imu.poll()]  # the last chunk's own end is cut short
    assert len(times) == 50
    np.testing.assert_allclose(np.diff(times), imu.period_s, rtol=1e-6)
