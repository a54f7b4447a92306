"""The setpoint keeper: latest wins, and the current setpoint is repeated every `keepalive_s`
while it is live (`hold_s` after the user gave it). When it expires nothing is repeated, so an
armed board's watchdog fails safe when the user's program stops commanding.

Paced lockstep (`SessionOptions.paced`): the live setpoint goes out once per feedback period, on
the board's control-tick grid, `PACE_PHASE_S` after a tick (the grid's ticks from the latest
FEEDBACK's sample time). A lockstep board queues setpoints (LOCKSTEP_QUEUE) and applies one per
tick, each answered by one FEEDBACK. At one FEEDBACK per tick the keeper stays a tick ahead: the
first setpoint goes out twice, and a slot sends one more whenever the board holds fewer than that
(the latest FEEDBACK's `ack_seq` against the frames sent since: after a stall or a frame lost on
the line; without a FEEDBACK to go by, one more per missed slot). So a send may be late by most of
two ticks (most of a period at lower rates) before a FEEDBACK is missed, and a stall longer than
that costs the periods it lasts, not the lead. A timer of the host's own drifts across the ticks
instead and, near one, its jitter puts two setpoints into one tick and none into the next. The
runner sends them from its I/O thread, so a busy caller (a ROS executor) cannot make them late.
"""

from __future__ import annotations

import math
from collections import deque

from host_sdk.errors import NackError
from host_sdk.limits import relimited
from host_sdk.session.counters import HostCounters
from host_sdk.session.options import EPS, SessionOptions
from host_sdk.session.wire import Wire
from protocol.codec.message import Message
from protocol.generated.constants import CONTROL_RATE_HZ, LOCKSTEP_QUEUE
from protocol.generated.messages import SetAckermann, SetConfig, SetWheelSpeeds

TICK_S = 1.0 / CONTROL_RATE_HZ
PACED_LATE_FRACTION = 0.5
"""Paced lockstep: a setpoint sent this fraction of `slot_span_s` after its slot, or later, counts
as late (LinkStatistics.paced_late)."""
HISTORY = 8
"""Paced lockstep: the setpoint frames remembered (seq and message), for the board's queue depth
and for telling a copy's refusal from a new one's."""
PACE_PHASE_S = 0.001
"""Paced lockstep: how long after a board tick (on the host's mapping of the board's clock) a
setpoint is sent: the tick before the one that applies it, which answers it with FEEDBACK (the
grid's anchor). Its frame time and the adapter's latency add to it, so it cannot reach the board
before that tick even with a clock-sync error of a millisecond."""


def queued_ahead(pace_s: float) -> int:
    """Paced lockstep: setpoints kept queued on the board ahead of the one its next tick applies.
    One at a FEEDBACK per tick; none at lower rates, where a slot's frame has the ticks between
    slots to arrive in (one more would be applied in the next tick, off the period's grid)."""
    return LOCKSTEP_QUEUE - 1 if pace_s < 2 * TICK_S - EPS else 0


def slot_span_s(pace_s: float) -> float:
    """Paced lockstep: from a slot to the tick that goes unanswered if the slot's frame has not
    landed by then (the period, and the ticks queued ahead). Less PACE_PHASE_S and the frame's
    time on the line, it is how late a send may be."""
    return (1 + queued_ahead(pace_s)) * pace_s


class SetpointKeeper:
    """The live setpoint, when it was last sent and when it expires."""

    __slots__ = (
        "_ack",
        "_expires",
        "_frames",
        "_n",
        "_options",
        "_refusal",
        "_refused",
        "_sent",
        "_seq",
        "_setpoint",
        "_slot",
        "_tick_s",
        "_wire",
    )

    def __init__(self, options: SessionOptions, wire: Wire, counters: HostCounters) -> None:
        self._options = options
        self._wire = wire
        self._n = counters
        self._setpoint: SetWheelSpeeds | SetAckermann | None = None
        self._seq = -1
        self._expires = 0.0
        self._sent = 0.0
        self._refusal: NackError | None = None
        """A setpoint the board refused (out of range, unsupported): raised on the user's next command."""
        self._tick_s: float | None = None
        """Paced lockstep: the host time of the latest FEEDBACK's tick (the grid's anchor)."""
        self._slot = -math.inf
        """Paced lockstep: the grid time of the last setpoint sent on the grid."""
        self._ack: int | None = None
        """The latest FEEDBACK's ack_seq since the live setpoint began (None: none yet)."""
        self._frames: deque[tuple[int, SetWheelSpeeds | SetAckermann]] = deque(maxlen=HISTORY)
        """The latest setpoint frames sent, oldest first: (seq, message)."""
        self._refused: SetWheelSpeeds | SetAckermann | None = None
        """The setpoint refused last: its copies' NACKs are not new refusals."""

    @property
    def live(self) -> bool:
        return self._setpoint is not None

    @property
    def last_seq(self) -> int:
        """The seq of the last setpoint frame sent (-1 before the first)."""
        return self._seq

    def request_sent(self, msg: Message) -> None:
        """A reliable request goes out. The board re-limits its running setpoint to a lowered speed
        limit (docs/control.md 4.4): the repeats sent after a SET_CONFIG carry the same values, or
        it refuses them."""
        if isinstance(msg, SetConfig) and self._setpoint is not None:
            self._setpoint = relimited(self._setpoint, msg.max_wheel_speed_mm_s)

    def command(
        self, msg: SetWheelSpeeds | SetAckermann, now: float, hold_s: float | None, pace_s: float | None = None
    ) -> int:
        """Send `msg` now and keep it live for `hold_s` (None: command_timeout). Returns its seq.

        Paced (`pace_s`, the period), while a setpoint is live already: `msg` replaces it and goes
        out at the next slot; returns the seq of the last one sent."""
        was_live = self._setpoint is not None
        self._setpoint = msg
        self._expires = now + (hold_s if hold_s is not None else self._options.command_timeout)
        if pace_s is None:
            return self._send(msg, now, keepalive=False)
        if was_live:
            return self._seq
        self._slot = self._slot_of(now, pace_s)  # the grid goes on after the slot this one stands for
        self._ack = None  # FEEDBACKs from before the pause say nothing of the queue now
        for _ in range(queued_ahead(pace_s)):
            self._send(msg, now, keepalive=False)  # the tick ahead
        return self._send(msg, now, keepalive=False)

    def ticked(self, host_time_s: float, ack_seq: int | None = None) -> None:
        """A FEEDBACK sampled at `host_time_s` (the board's tick, on the host's clock), answering
        the setpoint frame `ack_seq`."""
        self._tick_s = host_time_s
        if ack_seq is not None and self._setpoint is not None:
            self._ack = ack_seq

    def drop(self) -> None:
        """Stop repeating the setpoint (the board keeps it until its watchdog)."""
        self._setpoint = None

    def refused(self, error: NackError, req_seq: int | None = None) -> None:
        """The board refused a setpoint: stop repeating it and tell the user on the next command.
        A refusal of a copy of the setpoint refused last (paced lockstep sends some twice) is the
        same refusal: it neither drops a newer setpoint nor is told twice."""
        msg = next((m for seq, m in self._frames if seq == req_seq), None)
        if msg is not None and msg is self._refused:
            return
        self._refused = msg
        self._refusal = error
        self._setpoint = None

    def take_refusal(self) -> NackError | None:
        """The refusal not yet reported, once."""
        error, self._refusal = self._refusal, None
        return error

    def keep_alive(self, now: float, armed: bool, pace_s: float | None = None) -> None:
        """Repeat the live setpoint when due (only while armed: a disarmed board refuses it);
        paced (`pace_s`), at every slot of the grid."""
        setpoint = self._setpoint
        if setpoint is None:
            return
        if now >= self._expires - EPS:
            self._setpoint = None  # the user stopped commanding: go quiet, let the watchdog act
            return
        if not armed:
            return
        if pace_s is None:
            if now - self._sent >= self._options.keepalive - EPS:
                self._send(setpoint, now, keepalive=True)
        elif now >= (due := self._next_slot(pace_s)) - EPS:
            if now - due >= PACED_LATE_FRACTION * slot_span_s(pace_s):
                self._n.paced_late += 1
            # Late by whole periods (a stalled host): on from the slot now falls in, not a burst.
            self._slot = self._slot_of(now, pace_s)
            for _ in range(self._copies(now, round((self._slot - due) / pace_s), queued_ahead(pace_s))):
                self._send(setpoint, now, keepalive=True)

    def deadline(self, t: float, pace_s: float | None = None) -> float:
        """`t`, or earlier if a repeat or the expiry is due before it."""
        if self._setpoint is None:
            return t
        due = self._sent + self._options.keepalive if pace_s is None else self._next_slot(pace_s)
        return min(t, due, self._expires)

    def _copies(self, now: float, missed: int, lead: int) -> int:
        """How many frames this slot sends: one, and what refills the board's queue to `lead`
        ahead, at most `lead` (more would only supersede). The board holds what was sent after
        the latest FEEDBACK's ack_seq, less one per tick since that FEEDBACK; without a FEEDBACK
        to go by, one more per missed slot."""
        if not lead:
            return 1
        sent = [seq for seq, _ in self._frames]
        if self._ack is None or self._ack not in sent or self._tick_s is None:
            return 1 + min(missed, lead)
        held = len(sent) - 1 - sent.index(self._ack) - math.floor((now - self._tick_s) / TICK_S + EPS)
        return 1 + max(0, min(lead, lead - held))

    def _slot_of(self, t: float, pace_s: float) -> float:
        """The slot a setpoint sent at `t` stands for: that of the tick interval it lands in, which
        began at the latest tick not after `t` (`t` itself before any FEEDBACK)."""
        if self._tick_s is None:
            return t
        origin = self._tick_s - TICK_S + PACE_PHASE_S
        return origin + math.floor((t + PACE_PHASE_S - origin) / pace_s + EPS) * pace_s

    def _next_slot(self, pace_s: float) -> float:
        """The first slot more than half a period after the last one sent on."""
        if self._slot == -math.inf:
            return self._slot  # none sent on the grid yet: due at once
        if self._tick_s is None:
            return self._slot + pace_s
        origin = self._tick_s - TICK_S + PACE_PHASE_S
        return origin + (math.floor((self._slot + pace_s / 2 - origin) / pace_s) + 1) * pace_s

    def _send(self, msg: SetWheelSpeeds | SetAckermann, now: float, keepalive: bool) -> int:
        seq = self._wire.send(msg, now)
        self._seq = seq
        self._frames.append((seq, msg))
        self._sent = now
        self._n.setpoints_sent += 1
        if keepalive:
            self._n.keepalives_sent += 1
        return seq
