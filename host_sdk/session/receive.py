"""What each frame from the board does to the session: IDENTITY (the handshake, resets),
FEEDBACK (the board's state, odometry), NACK, the answers to reliable requests, PONG and LOG."""

from __future__ import annotations

from host_sdk.errors import SessionResetError
from host_sdk.session.events import FeedbackReceived, LogReceived
from host_sdk.session.lifecycle import Lifecycle, Parts
from host_sdk.session.options import LinkState
from host_sdk.session.reliable import nack_error
from protocol.codec.message import Delivery, Message
from protocol.generated.enums import FailsafeReason, IdentityReason, NackReason, Status
from protocol.generated.messages import (
    Arm,
    Config,
    Disarm,
    Feedback,
    GetConfig,
    Identity,
    Log,
    Nack,
    Pong,
    SetAckermann,
    SetConfig,
    SetWheelSpeeds,
)

_SESSION = int(Status.SESSION)


class Receiver:
    """Routes every frame received to the parts it concerns (and to Lifecycle when it ends or opens
    a session). It keeps no state of its own."""

    __slots__ = (
        "_arming",
        "_counters",
        "_emit",
        "_feedback",
        "_handshake",
        "_life",
        "_requests",
        "_setpoints",
        "_sync",
        "_wire",
    )

    def __init__(self, parts: Parts, life: Lifecycle) -> None:
        # The parts are unpacked: FEEDBACK comes at up to a few hundred frames a second.
        self._life = life
        self._counters = parts.counters
        self._wire = parts.wire
        self._handshake = parts.handshake
        self._sync = parts.sync
        self._setpoints = parts.setpoints
        self._arming = parts.arming
        self._requests = parts.requests
        self._feedback = parts.feedback
        self._emit = parts.emit

    def frame(self, msg: Message, seq: int, now: float) -> None:
        if isinstance(msg, Identity):
            self._on_identity(msg, now)
        elif isinstance(msg, Feedback):
            self._on_feedback(msg, now)
        self._wire.received(seq, now)
        if isinstance(msg, (Identity, Feedback)):
            return
        if isinstance(msg, Pong):
            self._sync.on_pong(msg, now, self._life.state is LinkState.OPEN)
        elif isinstance(msg, Log):
            self._emit(LogReceived(msg.level, msg.text))
        elif isinstance(msg, Nack):
            self._on_nack(msg, now)
        elif msg.DELIVERY is Delivery.RELIABLE:
            self._on_reply(msg, now)

    def _on_reply(self, msg: Message, now: float) -> None:
        if isinstance(msg, Config) and self._handshake.behind_hello(msg.req_seq):
            if self._life.state is LinkState.OPEN:
                self._handshake.config_answered(msg)
                self._life.check_ready(now)
            return
        req = self._requests.answered(msg)
        if req is None:
            return  # the answer to a retry we no longer wait for
        self._apply(req.msg, msg)
        self._requests.finish(req, msg, None)
        self._life.check_ready(now)
        self._requests.pump(now)

    def _apply(self, msg: Message, reply: Message) -> None:
        """What an answered request changed on the board."""
        if isinstance(reply, Config):
            self._handshake.config_read(reply)
        elif isinstance(msg, SetConfig):
            self._handshake.config_written(msg)
        elif isinstance(msg, Arm):
            self._arming.arm()
        elif isinstance(msg, Disarm):
            self._arming.clear()
            self._setpoints.drop()

    def _on_nack(self, msg: Nack, now: float) -> None:
        self._counters.nack(msg.reason.name)
        if msg.req_id == GetConfig.MSG_ID and self._handshake.behind_hello(msg.req_seq):
            return  # the GET_CONFIG behind a HELLO that did not open the session
        if msg.req_id in (SetWheelSpeeds.MSG_ID, SetAckermann.MSG_ID):
            self._on_setpoint_nack(msg, now)
            return
        req = self._requests.answered(msg)
        if req is not None:
            if msg.reason is NackReason.BOOT_ID_MISMATCH and isinstance(req.msg, Arm):
                error = SessionResetError(req.msg.boot_id, None, "ARM named a boot that is gone")
                self._requests.finish(req, None, error)
                self._life.lost(now, None, "the board refused ARM for another boot_id")
                return
            if msg.reason is NackReason.NO_SESSION:
                old = self._handshake.boot_id or 0
                self._requests.finish(req, None, SessionResetError(old, None, "the board has no session"))
                self._life.lost(now, None, f"{req.name} answered NO_SESSION")
                return
            self._requests.finish(req, None, nack_error(req.msg, msg))
            self._requests.pump(now)
        elif msg.reason is NackReason.NO_SESSION and self._life.state is LinkState.OPEN:
            self._life.lost(now, None, "the board answered NO_SESSION")

    def _on_setpoint_nack(self, msg: Nack, now: float) -> None:
        if self._life.state is not LinkState.OPEN:
            return
        reason = msg.reason
        if reason is NackReason.NO_SESSION:
            self._life.lost(now, None, "a setpoint was answered NO_SESSION")
            return
        if reason is NackReason.FAILSAFE:
            if self._arming.armed or self._arming.failsafe is None:
                try:
                    why = FailsafeReason(msg.detail)
                except ValueError:
                    why = FailsafeReason.NONE
                self._arming.enter_failsafe(why, predicted=False)
                self._setpoints.drop()
            return
        if reason is NackReason.NOT_ARMED:
            self._arming.disarm()
            self._setpoints.drop()
        else:
            request = SetWheelSpeeds if msg.req_id == SetWheelSpeeds.MSG_ID else SetAckermann
            self._setpoints.refused(nack_error(request, msg), msg.req_seq)

    def _on_identity(self, msg: Identity, now: float) -> None:
        if not self._handshake.heard(msg):
            if self._life.state is not LinkState.CLOSED:
                self._life.incompatible(msg)
            return
        if msg.reason is IdentityReason.BOOT:
            if self._life.state is LinkState.OPEN and msg.boot_id != self._handshake.boot_id:
                self._life.lost(now, msg.boot_id, "the board announced a new boot")  # sends HELLO
            elif self._life.state is LinkState.CONNECTING:
                self._life.hello(now)  # answer the announcement at once: ready one round trip after boot
            return
        if msg.reason is IdentityReason.HELLO_REJECTED:
            if self._handshake.sent_hello(msg.hello_seq):
                self._life.incompatible(msg)
            return
        ours = self._handshake.answered(msg.hello_seq)
        if self._life.state is LinkState.CONNECTING:
            if ours:  # else an answer to someone else's HELLO
                self._life.open(msg, now)
        elif self._life.state is LinkState.OPEN:
            if msg.boot_id != self._handshake.boot_id:
                self._life.lost(now, msg.boot_id, "an IDENTITY names a new boot")
                return
            # The board re-opened the session (a HELLO of ours that crossed the first answer):
            # it is disarmed and its duplicate memory is cleared.
            self._handshake.reopened(msg, now)
            if self._arming.armed:
                self._arming.disarm()
                self._setpoints.drop()

    def _on_feedback(self, msg: Feedback, now: float) -> None:
        # The receive path's per-frame work: the status bits tested as plain ints (IntFlag
        # operators cost a microsecond each), the rest in FeedbackTracker.sample.
        if self._life.state is not LinkState.OPEN:
            return
        if msg.boot_id != self._handshake.boot_id:
            self._wire.renumbered()
            self._life.lost(now, msg.boot_id, "FEEDBACK carries a new boot_id")
            return
        status = int(msg.status)
        if not status & _SESSION:
            self._life.lost(now, msg.boot_id, "the board reports no session")
            return
        self._counters.feedback_received += 1
        if self._arming.board_status(status, msg.failsafe_reason):
            self._setpoints.drop()
        sample = self._feedback.sample(msg, now, self._sync.clock)
        self._setpoints.ticked(sample.host_time_s, msg.ack_seq)  # paced lockstep's grid follows the board's ticks
        self._emit(FeedbackReceived(sample))
