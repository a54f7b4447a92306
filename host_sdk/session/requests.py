"""A reliable request (ARM, SET_CONFIG, GET_PID...) as the robot waits on it: sent, retried and
answered by the session's RequestQueue (reliable.py)."""

from __future__ import annotations

from host_sdk.errors import RoverLinkError
from protocol.codec.message import Message


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
