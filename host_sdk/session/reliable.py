"""Reliable requests (ARM, SET_CONFIG, GET_PID...): one in flight at a time (the firmware remembers
only the last one for its duplicate check), retried with the same seq, failed after `tries`,
answered by ACK, NACK or data. A new request never reuses the (msg_id, seq) of the previous one (a
PING takes the seq instead), so the firmware can never mistake it for a duplicate."""

from __future__ import annotations

from collections import deque
from collections.abc import Callable

from host_sdk.errors import NackError, RequestTimeoutError, RoverLinkError, SessionResetError
from host_sdk.session.counters import HostCounters
from host_sdk.session.events import Event, RequestFinished
from host_sdk.session.options import EPS, SessionOptions
from host_sdk.session.requests import Request
from host_sdk.session.wire import Wire
from protocol.codec.message import Message
from protocol.generated.enums import NackReason
from protocol.generated.messages import BY_ID, Ack, Config, LightsState, LinkStats, Nack, Pid, SaveConfig

REPLY_TYPES: dict[str, type[Message]] = {
    "GET_CONFIG": Config,
    "GET_PID": Pid,
    "GET_LINK_STATS": LinkStats,
    "GET_LIGHTS": LightsState,
}
"""Requests answered with data instead of an ACK."""


class RequestQueue:
    """The reliable requests waiting and the one in flight.

    The session tells it whether it is open (`link_open`) and the current boot (`boot_id`), and
    lets it burn a seq (`burn_seq`: a PING, so a new request never repeats the last one's (msg_id,
    seq), which the firmware would take for a duplicate). Every request done is announced
    (`emit`, a RequestFinished event).
    """

    def __init__(
        self,
        options: SessionOptions,
        wire: Wire,
        counters: HostCounters,
        *,
        link_open: Callable[[], bool],
        boot_id: Callable[[], int | None],
        burn_seq: Callable[[float], None],
        emit: Callable[[Event], None],
        on_send: Callable[[Message], None] = lambda _msg: None,
        silence_deadline: Callable[[float], float | None] = lambda _now: None,
    ) -> None:
        self._options = options
        self._wire = wire
        self._n = counters
        self._link_open = link_open
        self._boot_id = boot_id
        self._burn_seq = burn_seq
        self._emit = emit
        self._on_send = on_send
        """Told of each request as it first goes out (a SET_CONFIG re-limits the running setpoint)."""
        self._silence_deadline = silence_deadline
        """Until when the board's silence at a given time may still end in a reset (None: it talks)."""
        self._queue: deque[Request] = deque()
        self._inflight: Request | None = None
        self._last_key: tuple[int, int] | None = None
        """(msg_id, seq) of the last reliable request sent: the firmware's duplicate memory."""

    @property
    def deadline(self) -> float | None:
        """When the request in flight is due for a retry (None: none in flight)."""
        return self._inflight.deadline if self._inflight is not None else None

    def submit(self, msg: Message, now: float, tries: int | None, timeout_s: float | None) -> Request:
        o = self._options
        if timeout_s is None:
            timeout_s = o.save_timeout_s if isinstance(msg, SaveConfig) else o.request_timeout_s
        req = Request(msg, tries or o.request_tries, timeout_s, self._boot_id(), internal=False)
        self._queue.append(req)
        if self._link_open():
            self.pump(now)
        return req

    def push_front(self, msg: Message) -> None:
        """The session's own request (not bound to a boot), sent before anything queued."""
        o = self._options
        self._queue.appendleft(Request(msg, o.request_tries, o.request_timeout_s, None, True))

    def cancel(self, req: Request) -> None:
        if req in self._queue:
            self._queue.remove(req)
        if self._inflight is req:
            self._inflight = None
        if not req.done:
            req.done = True
            req.error = RequestTimeoutError(req.name, max(req.sent, 1), req.timeout_s)

    def pending(self, kind: type[Message]) -> bool:
        """A request of `kind` is queued or in flight."""
        inflight = [self._inflight] if self._inflight else []
        return any(isinstance(r.msg, kind) for r in [*self._queue, *inflight])

    def drain(self, inflight_first: bool) -> list[Request]:
        """Empty the queue; returns the requests not done, to be finished by the caller."""
        inflight = [self._inflight] if self._inflight else []
        pending = [*inflight, *self._queue] if inflight_first else [*self._queue, *inflight]
        self._queue.clear()
        self._inflight = None
        return [req for req in pending if not req.done]

    def note_sent(self, msg_id: int, seq: int) -> None:
        """A reliable request went out past the queue (the GET_CONFIG behind a HELLO)."""
        self._last_key = (msg_id, seq)

    def forget_sent(self) -> None:
        """A new firmware session remembers no request."""
        self._last_key = None

    def pump(self, now: float) -> None:
        """Send the next request if none is in flight and the session is open."""
        while self._inflight is None and self._queue and self._link_open():
            req = self._queue.popleft()
            if req.done:
                continue
            boot_id = self._boot_id()
            if req.boot_id is not None and req.boot_id != boot_id and not req.internal:
                # Queued for a session that a reset ended: never apply it to the new one.
                self.finish(req, None, SessionResetError(req.boot_id, boot_id, "before it was sent"))
                continue
            self._on_send(req.msg)
            if (req.msg.MSG_ID, self._wire.next_seq) == self._last_key:
                # The firmware would take this as a duplicate of the last request: burn the seq.
                self._burn_seq(now)
            req.seq = self._wire.send(req.msg, now)
            self._last_key = (req.msg.MSG_ID, req.seq)
            req.sent = 1
            req.deadline = now + req.timeout_s
            self._inflight = req
            self._n.requests_sent += 1

    def expire(self, now: float) -> None:
        """Retry the request in flight when its try timed out, or fail it after its last try."""
        req = self._inflight
        if req is None or now < req.deadline - EPS:
            return
        if req.sent >= req.tries and self._link_open():
            # Unanswered and the board gone quiet: it may be rebooting; a reset will fail the
            # request with SessionResetError, else it times out when that silence is too long.
            until = self._silence_deadline(now)
            if until is not None and now < until - EPS:
                req.deadline = until
                return
        if req.sent >= req.tries or not self._link_open():
            self._n.request_timeouts += 1
            self._inflight = None
            self.finish(req, None, RequestTimeoutError(req.name, req.sent, req.timeout_s))
            self.pump(now)
            return
        assert req.seq is not None
        self._wire.send(req.msg, now, seq=req.seq)  # a retry carries the same seq: applied once
        req.sent += 1
        req.deadline = now + req.timeout_s
        self._n.retries += 1

    def answered(self, reply: Message) -> Request | None:
        """The request in flight if `reply` (ACK, NACK or data) answers it; it is then no longer in flight."""
        req = self._inflight
        if req is None or req.seq is None:
            return None
        if isinstance(reply, (Ack, Nack)):
            ours = reply.req_id == req.msg.MSG_ID and reply.req_seq == req.seq
        else:
            expected = REPLY_TYPES.get(req.msg.NAME)
            ours = expected is not None and isinstance(reply, expected) and getattr(reply, "req_seq", -1) == req.seq
        if not ours:
            return None
        self._inflight = None
        return req

    def finish(self, req: Request, reply: Message | None, error: RoverLinkError | None) -> None:
        """`req` is done: answered by `reply` (already applied by the caller) or failed with `error`."""
        req.done = True
        req.reply = reply
        req.error = error
        self._emit(RequestFinished(req))


def nack_error(request: Message | type[Message], nack: Nack) -> NackError:
    """The NackError for a refused request: the field named by a field-index detail, and the value
    sent in it when `request` is the message itself (a class: the value is not known)."""
    field_name: str | None = None
    cls = BY_ID.get(nack.req_id, request if isinstance(request, type) else type(request))
    sent = ""
    if nack.reason in (NackReason.OUT_OF_RANGE, NackReason.INVALID_CONFIG) and nack.detail < len(cls.FIELDS):
        field_name = cls.FIELDS[nack.detail].name
        if nack.reason is NackReason.OUT_OF_RANGE and isinstance(request, cls):
            sent = f"sent {field_name} = {getattr(request, field_name)!r}"
    hints = {
        NackReason.OUT_OF_RANGE: sent,
        NackReason.ARMED: "disarm first (robot.disarm())",
        NackReason.EEPROM_ERROR: "the board's EEPROM did not verify; it may be worn out",
        NackReason.UNSUPPORTED: "this firmware build cannot do that",
        NackReason.INVALID_CONFIG: "fields are in range but inconsistent (steering min <= centre <= max, "
        "servo min < max, ESC min < neutral < max)",
    }
    return NackError(request.NAME, nack.reason, nack.detail, field_name, hints.get(nack.reason, ""))
