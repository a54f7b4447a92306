"""Host receive-path benchmark: the SDK against a FEEDBACK feeder on a pty, and pymavlink's mavutil
against a MAVLink feeder on a pty, at the same rates, in the same run.

What is measured, per rate (50, 100, 500 Hz by default):

- **SDK, receiving**: `Robot.connect(pty)` to a feeder process that plays a board (answers HELLO,
  GET_CONFIG, ARM, PING; streams FEEDBACK at the rate). The robot is armed and idle; the
  benchmark's main thread sleeps. CPU time of the whole process (getrusage: the I/O thread's
  reading, decoding, session, odometry and callbacks) per FEEDBACK frame received, and wake-ups
  (voluntary context switches) per frame.
- **mavutil, receiving**: `mavutil.mavlink_connection(pty)` with `recv_match(blocking=True)` in a
  loop, fed a MAVLink 2 stream of the ardupilotmega message nearest FEEDBACK's payload size at
  the same rate. CPU time per message, wake-ups per message.
- **SDK, driving**: as above while the main thread calls `drive()` at 100 Hz: `drive()` latency
  p50/p99/max (perf_counter around the call), and CPU per FEEDBACK frame; once without and once
  with a CPU hog (a busy-looping process) on the other core.

The receiving side (SDK or mavutil) is pinned to core 0; the feeders and the hog to core 1.

The feeders are separate processes: their CPU is not counted. Ratios are SDK / mavutil from this
run. Run: `python benchmarks/host.py` (about a minute), `--quick` for a smoke run, `--json FILE`
to keep the figures.
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing as mp
import os
import random
import resource
import select
import statistics
import sys
import time
import tty
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import asdict, dataclass
from typing import Any

from codec_peers.mavlink import choose_mavlink_message, mavlink_module, random_field_values
from pymavlink import mavutil

from host_sdk import Robot
from host_sdk.framing import Frame, FrameDecoder, encode_frame
from host_sdk.profiles import PROFILES
from protocol.generated import enums, messages
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH

PROFILE = PROFILES["diffdrive-tb6612"]
BOOT_ID = 0x5EED1234


# == the feeders (child processes) ===================================================================
def _pty() -> tuple[int, int, str]:
    """A pty pair in raw mode: (master fd, slave fd, slave path). The slave fd stays open while the
    feeder runs: with no slave open, reading the master fails (EIO) before the reader opens it."""
    master, slave = os.openpty()
    tty.setraw(master)
    tty.setraw(slave)
    return master, slave, os.ttyname(slave)


def _board_answers(msg: messages.Message, seq: int, state: dict[str, Any], now_us: int) -> list[messages.Message]:
    """What a board answers to one host frame (just enough of a board for a session)."""
    if isinstance(msg, messages.Hello):
        state["session"] = True
        return [
            messages.Identity(
                PROTOCOL_VERSION,
                SPEC_HASH,
                (0, 1, 0),
                PROFILE.board,
                PROFILE.capabilities,
                BOOT_ID,
                now_us // 1000,
                enums.IdentityReason.HELLO_ACCEPTED,
                seq,
                250,
                enums.FeedbackMode.STREAM,
                min(state["rate"], 255),
                PROFILE.example,
            )
        ]
    if isinstance(msg, messages.GetConfig):
        return [messages.Config(req_seq=seq, **PROFILE.config.fields())]
    if isinstance(msg, (messages.Arm, messages.Disarm)):
        state["armed"] = isinstance(msg, messages.Arm)
        return [messages.Ack(msg.MSG_ID, seq)]
    if isinstance(msg, messages.Ping):
        return [messages.Pong(msg.host_time_us, now_us & 0xFFFFFFFF)]
    if isinstance(msg, (messages.SetWheelSpeeds, messages.SetAckermann)):
        state["ack_seq"] = seq
    return []


def roverlink_feeder(master: int, rate: float, stop: Any) -> None:
    """A board on the pty's master end: answers the session, streams FEEDBACK at `rate`."""
    decoder = FrameDecoder()
    state: dict[str, Any] = {"session": False, "armed": False, "rate": int(rate), "ack_seq": 0}
    t0 = time.monotonic()
    period = 1.0 / rate
    next_fb = t0
    seq = tick = 0
    counts = [0, 0]
    while not stop.is_set():
        now = time.monotonic()
        ready, _, _ = select.select([master], [], [], max(0.0, next_fb - now))
        now_us = int((time.monotonic() - t0) * 1e6)
        out = b""
        if ready:
            try:
                data = os.read(master, 4096)
            except OSError:
                return
            for event in decoder.feed(data):
                if isinstance(event, Frame):
                    for answer in _board_answers(event.message, event.seq, state, now_us):
                        out += encode_frame(answer, seq)
                        seq = (seq + 1) & 0xFF
        if state["session"] and time.monotonic() >= next_fb:
            next_fb += period
            tick = (tick + 1) & 0xFFFF
            counts[0] += 13
            counts[1] += 17
            status = enums.Status.SESSION | (enums.Status.ARMED if state["armed"] else enums.Status(0))
            fb = messages.Feedback(
                BOOT_ID,
                now_us & 0xFFFFFFFF,
                tick,
                state["ack_seq"],
                tick,
                status,
                enums.FailsafeReason.NONE,
                (counts[0], counts[1]),
                (300, 310),
                (400, 410),
                0,
            )
            out += encode_frame(fb, seq)
            seq = (seq + 1) & 0xFF
        if out:
            try:
                os.write(master, out)
            except OSError:
                return


def mavlink_feeder(master: int, rate: float, stop: Any) -> None:
    """A MAVLink 2 stream on the pty's master end: one message of FEEDBACK's size per period."""
    mod = mavlink_module()
    cls = choose_mavlink_message(mod, messages.Feedback.PAYLOAD_SIZE, len(messages.Feedback.FIELDS), None)
    mav = mod.MAVLink(None, srcSystem=1, srcComponent=1)
    rng = random.Random(1)
    period = 1.0 / rate
    next_t = time.monotonic()
    while not stop.is_set():
        next_t += period
        try:
            os.write(master, cls(*random_field_values(cls, rng)).pack(mav))
        except OSError:
            return
        delay = next_t - time.monotonic()
        if delay > 0:
            time.sleep(delay)


def mavlink_message_name() -> str:
    mod = mavlink_module()
    cls = choose_mavlink_message(mod, messages.Feedback.PAYLOAD_SIZE, len(messages.Feedback.FIELDS), None)
    return f"{cls.msgname} ({cls.unpacker.size} B payload)"


@contextmanager
def feeding(feeder: Callable[[int, float, Any], None], rate: float) -> Iterator[str]:
    """Run `feeder` on a new pty's master in a child process; yields the slave's path."""
    master, slave, path = _pty()
    ctx = mp.get_context("fork")
    stop = ctx.Event()
    proc = ctx.Process(target=_feed_on_core_1, args=(feeder, master, rate, stop), daemon=True)
    proc.start()
    try:
        yield path
    finally:
        stop.set()
        proc.join(timeout=3)
        if proc.is_alive():
            proc.kill()
            proc.join()
        os.close(master)
        os.close(slave)


def _normal_priority() -> None:
    """A child process leaves the real-time class the measuring process may be in (--rt)."""
    if os.sched_getscheduler(0) != os.SCHED_OTHER:
        os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))


def _feed_on_core_1(feeder: Callable[[int, float, Any], None], master: int, rate: float, stop: Any) -> None:
    # The feeder plays the board: it runs beside the hog on core 1, leaving core 0 to the host.
    _normal_priority()
    with _pinned(1):
        feeder(master, rate, stop)


def _hog(stop: Any) -> None:
    _normal_priority()
    with _pinned(1):
        while not stop.is_set():
            pass


@contextmanager
def hog(enabled: bool) -> Iterator[None]:
    """A busy-looping process on core 1 (when `enabled`)."""
    if not enabled:
        yield
        return
    ctx = mp.get_context("fork")
    stop = ctx.Event()
    proc = ctx.Process(target=_hog, args=(stop,), daemon=True)
    proc.start()
    try:
        yield
    finally:
        stop.set()
        proc.join(timeout=3)


@contextmanager
def _pinned(core: int) -> Iterator[None]:
    old = os.sched_getaffinity(0)
    if len(old) > 1 and core in old:
        os.sched_setaffinity(0, {core})
    try:
        yield
    finally:
        os.sched_setaffinity(0, old)


# == measuring ====================================================================================
@dataclass
class Usage:
    cpu_s: float
    wakeups: int

    @classmethod
    def now(cls) -> Usage:
        r = resource.getrusage(resource.RUSAGE_SELF)
        return cls(r.ru_utime + r.ru_stime, r.ru_nvcsw)

    def __sub__(self, other: Usage) -> Usage:
        return Usage(self.cpu_s - other.cpu_s, self.wakeups - other.wakeups)


@dataclass
class Row:
    stack: str
    rate_hz: float
    frames: int
    cpu_us_per_frame: float
    wakeups_per_frame: float
    drive_p50_us: float | None = None
    drive_p99_us: float | None = None
    drive_max_us: float | None = None
    hog: bool = False


def measure_sdk(rate: float, seconds: float, *, drive_hz: float = 0.0, with_hog: bool = False) -> Row:
    with feeding(roverlink_feeder, rate) as path, _pinned(0):
        robot = Robot.connect(path, profile=PROFILE.name, feedback_hz=0, timeout_s=5.0)
        try:
            latencies: list[float] = []
            with hog(with_hog):
                if drive_hz:
                    robot.arm()
                    warm = time.monotonic() + 0.5
                    while time.monotonic() < warm:
                        robot.drive(0.2, 0.1)
                        time.sleep(1 / drive_hz)
                else:
                    time.sleep(0.5)  # warm up (disarmed: the session only receives)
                before, fb0 = Usage.now(), robot.stats.feedback_received
                end = time.monotonic() + seconds
                if drive_hz:
                    period = 1.0 / drive_hz
                    next_t = time.monotonic()
                    while time.monotonic() < end:
                        t = time.perf_counter()
                        robot.drive(0.2, 0.1)
                        latencies.append(time.perf_counter() - t)
                        next_t += period
                        time.sleep(max(0.0, next_t - time.monotonic()))
                else:
                    time.sleep(seconds)
                used, frames = Usage.now() - before, robot.stats.feedback_received - fb0
        finally:
            robot.close()
    row = Row("roverlink", rate, frames, used.cpu_s * 1e6 / max(frames, 1), used.wakeups / max(frames, 1))
    if latencies:
        lat = sorted(latencies)
        row.drive_p50_us = statistics.median(lat) * 1e6
        row.drive_p99_us = lat[min(len(lat) - 1, math.ceil(0.99 * len(lat)) - 1)] * 1e6
        row.drive_max_us = lat[-1] * 1e6
        row.hog = with_hog
    return row


def measure_mavutil(rate: float, seconds: float) -> Row:
    with feeding(mavlink_feeder, rate) as path, _pinned(0):
        conn = mavutil.mavlink_connection(path, baud=115200)
        try:
            warm = time.monotonic() + 0.5
            while time.monotonic() < warm:
                conn.recv_match(blocking=True, timeout=0.5)
            before, n = Usage.now(), 0
            end = time.monotonic() + seconds
            while time.monotonic() < end:
                if conn.recv_match(blocking=True, timeout=0.5) is not None:
                    n += 1
            used = Usage.now() - before
        finally:
            conn.close()
    return Row("mavutil", rate, n, used.cpu_s * 1e6 / max(n, 1), used.wakeups / max(n, 1))


# == report ========================================================================================
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rates", default="50,100,500", help="FEEDBACK (and MAVLink) rates in Hz (default 50,100,500)")
    parser.add_argument("--seconds", type=float, default=5.0, help="measured time per case (default 5)")
    parser.add_argument("--quick", action="store_true", help="1 s per case (a smoke run)")
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    parser.add_argument(
        "--rt",
        action="store_true",
        help="run the receiving process under SCHED_FIFO (as a robot's control process would be, "
        "e.g. with chrt): other processes on its core no longer preempt it (needs root)",
    )
    args = parser.parse_args(argv)
    if args.rt:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(10))
    seconds = 1.0 if args.quick else args.seconds
    rates = [float(r) for r in args.rates.split(",")]
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    policy = "SCHED_FIFO" if args.rt else "normal priority"
    print(
        f"host receive path: {os.cpu_count()} cores (load average {load}), Python {sys.version.split()[0]}, "
        f"{seconds:g} s per case, receiver at {policy}"
    )
    print(
        f"peer: pymavlink mavutil, MAVLink 2 {mavlink_message_name()}; RoverLink FEEDBACK "
        f"({messages.Feedback.PAYLOAD_SIZE} B payload)\n"
    )
    rows: list[Row] = []
    print(f"{'rate':>6} {'stack':<10} {'frames':>7} {'CPU us/frame':>13} {'wake-ups/frame':>15}")
    for rate in rates:
        for row in (measure_sdk(rate, seconds), measure_mavutil(rate, seconds)):
            rows.append(row)
            cpu, wakeups = f"{row.cpu_us_per_frame:>13.1f}", f"{row.wakeups_per_frame:>15.2f}"
            print(f"{rate:>5g}Hz {row.stack:<10} {row.frames:>7} {cpu} {wakeups}")
        sdk, mav = rows[-2], rows[-1]
        print(
            f"{'':>6} {'ratio':<10} {'':>7} {sdk.cpu_us_per_frame / mav.cpu_us_per_frame:>12.2f}x "
            f"{sdk.wakeups_per_frame / max(mav.wakeups_per_frame, 1e-9):>14.2f}x"
        )
    print("\ndrive() at 100 Hz while receiving (SDK on core 0; feeder and hog on core 1):")
    print(f"{'rate':>6} {'hog':<5} {'CPU us/frame':>13} {'p50 us':>8} {'p99 us':>8} {'max us':>9}")
    for rate in rates:
        for with_hog in (False, True):
            row = measure_sdk(rate, seconds, drive_hz=100.0, with_hog=with_hog)
            rows.append(row)
            print(
                f"{rate:>5g}Hz {'yes' if with_hog else 'no':<5} {row.cpu_us_per_frame:>13.1f} "
                f"{row.drive_p50_us:>8.1f} {row.drive_p99_us:>8.1f} {row.drive_max_us:>9.1f}"
            )
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump([asdict(r) for r in rows], f, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
