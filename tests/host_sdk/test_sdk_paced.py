"""Paced lockstep's setpoint grid (host_sdk/session/setpoints.py), sans I/O: the times are arguments.

The board queues setpoints (LOCKSTEP_QUEUE) and applies one per control tick, each answered by one
FEEDBACK. Paced, they go out PACE_PHASE_S after a board tick (from the latest FEEDBACK's sample
time), once a period, whatever the polling does; at one FEEDBACK per tick, a tick ahead.
"""

from __future__ import annotations

import random

import pytest

from host_sdk.errors import NackError
from host_sdk.session.counters import HostCounters
from host_sdk.session.options import SessionOptions
from host_sdk.session.setpoints import PACE_PHASE_S, TICK_S, SetpointKeeper
from host_sdk.session.wire import Wire
from protocol.generated.constants import LOCKSTEP_QUEUE
from protocol.generated.enums import NackReason
from protocol.generated.messages import SetWheelSpeeds

STEP_S = 0.0001
"""How often the test polls (a runner polls when `deadline` says, or earlier)."""


class Grid:
    def __init__(self) -> None:
        self.n = HostCounters()
        self.keeper = SetpointKeeper(SessionOptions(), Wire(self.n), self.n)
        self.sent: list[float] = []
        """When `poll` sent one (not the commands sent at once)."""
        self.frames: list[float] = []
        """When each setpoint frame went out, the commands' too (`command`)."""

    def command(self, left: int, t: float, pace_s: float) -> None:
        before = self.n.setpoints_sent
        self.keeper.command(SetWheelSpeeds(left, left), t, hold_s=1.0, pace_s=pace_s)
        self.frames += [t] * (self.n.setpoints_sent - before)

    def poll(self, t0: float, t1: float, pace_s: float, skip: tuple[float, float] = (0.0, 0.0)) -> None:
        """Poll every STEP_S from t0 to t1 (not within `skip`), noting when a setpoint went out."""
        for i in range(round((t1 - t0) / STEP_S)):
            t = t0 + i * STEP_S
            if skip[0] <= t < skip[1]:
                continue
            before = self.n.setpoints_sent
            self.keeper.keep_alive(t, armed=True, pace_s=pace_s)
            if self.n.setpoints_sent > before:
                self.sent.append(t)
                self.frames += [t] * (self.n.setpoints_sent - before)


FRAME_S = 0.0012
"""A SET_WHEEL_SPEEDS frame's time on the line at 115200 baud, and a little of the adapter's."""


def unanswered_ticks(frames: list[float], first: int, last: int) -> list[int]:
    """The ticks first..last (at k * TICK_S) that applied no setpoint, on a board that queues
    LOCKSTEP_QUEUE of them (a frame into a full queue supersedes the newest) and applies the oldest
    at each tick, as the firmware does."""
    arrivals = sorted(t + FRAME_S for t in frames)
    queue = 0
    missed = []
    for k in range(first, last + 1):
        while arrivals and arrivals[0] < k * TICK_S:
            arrivals.pop(0)
            queue = min(queue + 1, LOCKSTEP_QUEUE)
        if queue:
            queue -= 1
        else:
            missed.append(k)
    return missed


def test_paced_setpoints_go_out_just_after_each_board_tick_a_tick_ahead() -> None:
    g = Grid()
    g.keeper.ticked(0.0)  # a FEEDBACK of the tick at t = 0
    g.command(100, 0.0034, TICK_S)  # at once, twice: none live, and the board's queue takes the second
    assert g.frames == [0.0034, 0.0034]
    g.poll(0.0034, 0.05, TICK_S)
    assert g.n.setpoints_sent == 6
    assert g.sent == pytest.approx([k * TICK_S + PACE_PHASE_S for k in range(1, 5)], abs=STEP_S * 1.01)
    assert unanswered_ticks(g.frames, 1, 5) == []


def test_a_new_command_waits_for_the_next_slot_and_a_stall_costs_only_its_own_ticks() -> None:
    g = Grid()
    g.keeper.ticked(0.0)
    g.command(100, 0.0005, TICK_S)
    g.poll(0.0005, 0.0055, TICK_S)
    sent = g.n.setpoints_sent
    g.command(200, 0.0055, TICK_S)
    assert g.n.setpoints_sent == sent  # replaces the live one: goes out at 0.011, not now
    g.poll(0.0055, 0.1, TICK_S, skip=(0.031, 0.0575))  # the host stalled for 26.5 ms
    expected = [0.011, 0.021, 0.0575, 0.061, 0.071, 0.081, 0.091]  # one late send, then the grid again
    assert g.sent == pytest.approx(expected, abs=STEP_S * 1.01)
    assert g.frames.count(g.sent[2]) == 2  # the missed slots refill the board's queue, no more
    assert g.n.paced_late == 1  # counted once, not once per period missed
    # The queued setpoint covered the tick at 0.04; the one at 0.05 had none; from 0.06 on, the
    # tick ahead is back.
    assert unanswered_ticks(g.frames, 1, 9) == [5]


FEEDBACK_S = 0.0035
"""A FEEDBACK's time on the line at 115200 baud: when after its tick the host has it."""


def closed_loop(g: Grid, seconds: float, lost: int, stalls: list[tuple[float, float]]) -> list[int]:
    """The keeper polled every STEP_S (not within `stalls`) against a lockstep board whose
    FEEDBACKs it is given (`ticked`, with their ack_seq), the `lost`-th frame lost on the line.
    Returns the ticks that applied no setpoint."""
    queue: list[int] = []
    feedback: list[tuple[float, float, int]] = []  # (when the host has it, its tick, ack_seq)
    missed = []
    k = 1
    g.command(100, 0.0005, TICK_S)
    for i in range(5, round(seconds / STEP_S)):
        t = i * STEP_S
        if t >= k * TICK_S - STEP_S / 2:
            arrived = [
                n for n, sent in enumerate(g.frames) if n != lost and (k - 1) * TICK_S <= sent + FRAME_S < k * TICK_S
            ]
            for n in arrived:
                queue = [*queue, n] if len(queue) < LOCKSTEP_QUEUE else [*queue[:-1], n]
            if queue:
                feedback.append((k * TICK_S + FEEDBACK_S, k * TICK_S, queue.pop(0) & 0xFF))
            else:
                missed.append(k)
            k += 1
        while feedback and feedback[0][0] <= t:
            _, tick_s, ack = feedback.pop(0)
            g.keeper.ticked(tick_s, ack)
        if not any(a <= t < b for a, b in stalls):
            g.poll(t, t + STEP_S, TICK_S)
    return missed


def test_a_frame_lost_on_the_line_does_not_lose_the_tick_ahead() -> None:
    """The FEEDBACKs show the board one setpoint short after a frame is lost: the next slot sends
    one more, so a later send 13.5 ms late still costs no tick (counting missed slots alone, the lead
    would stay lost until a stall cost one)."""
    g = Grid()
    g.keeper.ticked(0.0)
    assert closed_loop(g, 0.5, lost=20, stalls=[(0.3105, 0.3245)]) == []  # the slot at 0.311 met 13.5 ms late
    g = Grid()
    g.keeper.ticked(0.0)
    assert closed_loop(g, 0.5, lost=-1, stalls=[(0.3011, 0.3361)]) == [33]  # 35 ms: the queue runs dry once


def test_a_send_late_by_most_of_two_ticks_misses_no_tick() -> None:
    """The host as the runner drives it: it wakes when `deadline` says, late by up to 17 ms in one
    slot out of five (a loaded host; the old scheme lost a tick to anything over 8 ms)."""
    rng = random.Random(7)
    g = Grid()
    g.keeper.ticked(0.0)
    g.command(100, 0.0005, TICK_S)
    t = 0.0005
    late = 0
    while t < 20.0:
        due = g.keeper.deadline(t + 1.0, pace_s=TICK_S)
        delay = rng.uniform(0.0, 0.017) if rng.random() < 0.2 else rng.uniform(0.0, 0.0005)
        late += delay > TICK_S - PACE_PHASE_S - FRAME_S
        t = max(t, due) + delay
        before = g.n.setpoints_sent
        g.keeper.command(SetWheelSpeeds(100, 100), t, hold_s=1.0, pace_s=TICK_S)  # the user's 100 Hz
        g.keeper.keep_alive(t, armed=True, pace_s=TICK_S)
        g.frames += [t] * (g.n.setpoints_sent - before)
    assert late > 100  # sends past the one-tick slack happened
    assert unanswered_ticks(g.frames, 1, 1990) == []


def test_the_grid_follows_the_boards_ticks_and_spans_its_period() -> None:
    """Every other tick (50 Hz): slots one tick before each tick that answers; a later FEEDBACK
    moves the grid with the board's clock (which drifts against the host's)."""
    g = Grid()
    g.keeper.ticked(0.0)
    g.keeper.command(SetWheelSpeeds(100, 100), 0.0002, hold_s=1.0, pace_s=2 * TICK_S)
    g.poll(0.0002, 0.03, 2 * TICK_S)
    g.keeper.ticked(0.0403)  # the board's clock runs 0.3 ms ahead by now
    g.poll(0.03, 0.07, 2 * TICK_S)
    assert g.sent == pytest.approx([0.011, 0.0313, 0.0513], abs=STEP_S * 1.01)


def test_a_setpoint_half_its_slack_late_is_counted_and_a_punctual_one_not() -> None:
    """At 100 Hz a send may be late by most of two ticks: half of that, a period, counts."""
    g = Grid()
    g.keeper.ticked(0.0)
    g.keeper.command(SetWheelSpeeds(100, 100), 0.0005, hold_s=1.0, pace_s=TICK_S)
    g.poll(0.0005, 0.03, TICK_S)  # every slot on time
    assert g.n.paced_late == 0
    g.poll(0.03, 0.06, TICK_S, skip=(0.0305, 0.0412))  # the slot at 0.031 is met at 0.0412: 10.2 ms late
    assert g.n.paced_late == 1
    g.poll(0.06, 0.09, TICK_S, skip=(0.0605, 0.0700))  # 9 ms late: within half the slack
    assert g.n.paced_late == 1


def test_the_refusal_of_a_setpoints_copy_is_the_same_refusal() -> None:
    """The first paced setpoint goes out twice, so a refused one is refused twice: the second NACK
    neither drops the command given after the first nor is told again."""
    g = Grid()
    g.keeper.ticked(0.0)
    g.command(900, 0.0005, TICK_S)
    assert g.frames == [0.0005, 0.0005]  # seqs 0 and 1, the same setpoint
    refusal = NackError("SET_WHEEL_SPEEDS", NackReason.OUT_OF_RANGE, 0, "left_mm_s")
    g.keeper.refused(refusal, 0)
    assert not g.keeper.live and g.keeper.take_refusal() is refusal
    g.command(100, 0.004, TICK_S)  # the user's next command, after the error
    g.keeper.refused(NackError("SET_WHEEL_SPEEDS", NackReason.OUT_OF_RANGE, 0, "left_mm_s"), 1)
    assert g.keeper.live and g.keeper.take_refusal() is None
    g.keeper.refused(refusal, 2)  # a refusal of the new one is new
    assert not g.keeper.live and g.keeper.take_refusal() is refusal
