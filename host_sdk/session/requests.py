"""Reliable requests (ARM, SET_CONFIG, GET_PID...): one in flight at a time, retried with the same
seq, answered by ACK, NACK or data."""

from __future__ import annotations

from host_sdk.errors import RequestTimeoutError, RoverLinkError, SessionResetError
from host_sdk.limits import relimited
from host_sdk.session.events import LinkState, RequestFinished
from host_sdk.session.output import EPS, Output
from protocol.codec.message import Message
from protocol.generated.messages import Ack, Arm, Config, Disarm, LinkStats, Nack, Pid, SaveConfig, SetConfig

CONFIG_FIELDS = tuple(f.name for f in SetConfig.FIELDS)
REPLY_TYPES: dict[str, type[Message]] = {"GET_CONFIG": Config, "GET_PID": Pid, "GET_LINK_STATS": LinkStats}
"""Requests answered with data instead of an ACK."""


class Request:
    """A reliable request and, once `done`, its `reply` (ACK or data) or its `error`."""

    __slots__ = (
        "boot_id",
        "deadline",
        "done",
        "error",
        "internal",
        "msg",
        "reply",
        "sent",
        "seq",
        "timeout_s",
        "tries",
    )

    def __init__(self, msg: Message, tries: int, timeout_s: float, boot_id: int | None, internal: bool) -> None:
        self.msg = msg
        self.tries = tries
        self.timeout_s = timeout_s
        self.boot_id = boot_id
        self.internal = internal
        self.seq: int | None = None
        self.sent = 0
        self.deadline = 0.0
        self.done = False
        self.reply: Message | None = None
        self.error: RoverLinkError | None = None

    @property
    def name(self) -> str:
        return self.msg.NAME

    @property
    def budget_s(self) -> float:
        """How long its every try may take, with room for the last answer to arrive."""
        return self.tries * self.timeout_s + 0.5

    def __repr__(self) -> str:
        state = "done" if self.done else f"sent {self.sent}x"
        return f"<Request {self.msg.NAME} seq={self.seq} {state}>"


def config_of(msg: Config) -> SetConfig:
    return SetConfig(**{name: getattr(msg, name) for name in CONFIG_FIELDS})


class Requests(Output):
    """The session's reliable-request queue."""

    def submit(self, msg: Message, now: float, *, tries: int | None = None, timeout_s: float | None = None) -> Request:
        """Queue a reliable request; it is sent when the session is open and none is in flight."""
        if timeout_s is None:
            timeout_s = self.options.save_timeout_s if isinstance(msg, SaveConfig) else self.options.request_timeout_s
        req = Request(msg, tries or self.options.request_tries, timeout_s, self.boot_id, internal=False)
        self._queue.append(req)
        if self._state is LinkState.OPEN:
            self._pump_queue(now)
        return req

    def cancel(self, req: Request) -> None:
        """Give up on a request (its answer, if it comes, is ignored)."""
        if req in self._queue:
            self._queue.remove(req)
        if self._inflight is req:
            self._inflight = None
        if not req.done:
            req.done = True
            req.error = RequestTimeoutError(req.name, max(req.sent, 1), req.timeout_s)

    # -- reliable requests ---------------------------------------------------------------------------
    def _pump_queue(self, now: float) -> None:
        while self._inflight is None and self._queue and self._state is LinkState.OPEN:
            req = self._queue.popleft()
            if req.done:
                continue
            if req.boot_id is not None and req.boot_id != self.boot_id and not req.internal:
                # Queued for a session that a reset ended: never apply it to the new one.
                self._finish(req, None, SessionResetError(req.boot_id, self.boot_id, "before it was sent"))
                continue
            if isinstance(req.msg, SetConfig) and self._setpoint is not None:
                # The board re-limits its running setpoint to a lowered speed limit; the repeats
                # sent after this SET_CONFIG must carry the same values, or it refuses them.
                self._setpoint = relimited(self._setpoint, req.msg.max_wheel_speed_mm_s)
            if (req.msg.MSG_ID, self._tx_seq) == self._last_reliable_key:
                # The firmware would take this as a duplicate of the last request: burn the seq.
                self._send_ping(now)
            req.seq = self._send(req.msg, now)
            self._last_reliable_key = (req.msg.MSG_ID, req.seq)
            req.sent = 1
            req.deadline = now + req.timeout_s
            self._inflight = req
            self._n.requests_sent += 1

    def _expire_inflight(self, now: float) -> None:
        req = self._inflight
        if req is None or now < req.deadline - EPS:
            return
        if req.sent >= req.tries or self._state is not LinkState.OPEN:
            self._n.request_timeouts += 1
            self._inflight = None
            self._finish(req, None, RequestTimeoutError(req.name, req.sent, req.timeout_s))
            self._pump_queue(now)
            return
        assert req.seq is not None
        self._send(req.msg, now, seq=req.seq)  # a retry carries the same seq: applied once
        req.sent += 1
        req.deadline = now + req.timeout_s
        self._n.retries += 1

    def _finish(self, req: Request, reply: Message | None, error: RoverLinkError | None) -> None:
        req.done = True
        req.reply = reply
        req.error = error
        if error is None and reply is not None:
            self._apply_reply(req, reply)
        self._events.append(RequestFinished(req))

    def _apply_reply(self, req: Request, reply: Message) -> None:
        msg = req.msg
        if isinstance(reply, Config):
            self._config = config_of(reply)
            self._config_fresh = True
        elif isinstance(msg, SetConfig):
            self._config = msg
        elif isinstance(msg, Arm):
            self._armed = True
            self._failsafe = None
            self._failsafe_predicted = False
        elif isinstance(msg, Disarm):
            self._armed = False
            self._failsafe = None
            self._failsafe_predicted = False
            self._setpoint = None

    def _match(self, reply: Message) -> Request | None:
        req = self._inflight
        if req is None or req.seq is None:
            return None
        if isinstance(reply, (Ack, Nack)):
            return req if reply.req_id == req.msg.MSG_ID and reply.req_seq == req.seq else None
        expected = REPLY_TYPES.get(req.msg.NAME)
        if expected is not None and isinstance(reply, expected) and getattr(reply, "req_seq", -1) == req.seq:
            return req
        return None
