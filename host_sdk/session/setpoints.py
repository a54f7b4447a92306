"""The setpoint keeper: latest wins, and the current setpoint is repeated every `keepalive_s`
while it is live (`hold_s` after the user gave it). When it expires nothing is repeated, so an
armed board's watchdog fails safe when the user's program stops commanding."""

from __future__ import annotations

from host_sdk.errors import NackError
from host_sdk.limits import relimited
from host_sdk.session.counters import HostCounters
from host_sdk.session.options import EPS, SessionOptions
from host_sdk.session.wire import Wire
from protocol.codec.message import Message
from protocol.generated.messages import SetAckermann, SetConfig, SetWheelSpeeds


class SetpointKeeper:
    """The live setpoint, when it was last sent and when it expires."""

    __slots__ = ("_expires", "_n", "_options", "_refusal", "_sent", "_seq", "_setpoint", "_wire")

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

    def command(self, msg: SetWheelSpeeds | SetAckermann, now: float, hold_s: float | None) -> int:
        """Send `msg` now and keep it live for `hold_s` (None: command_timeout). Returns its seq."""
        self._setpoint = msg
        self._expires = now + (hold_s if hold_s is not None else self._options.command_timeout)
        return self._send(msg, now, keepalive=False)

    def drop(self) -> None:
        """Stop repeating the setpoint (the board keeps it until its watchdog)."""
        self._setpoint = None

    def refused(self, error: NackError) -> None:
        """The board refused a setpoint: stop repeating it (setpoints are not kept: which one is
        unknown) and tell the user on the next command."""
        self._refusal = error
        self._setpoint = None

    def take_refusal(self) -> NackError | None:
        """The refusal not yet reported, once."""
        error, self._refusal = self._refusal, None
        return error

    def keep_alive(self, now: float, armed: bool) -> None:
        """Repeat the live setpoint when due (only while armed: a disarmed board refuses it)."""
        setpoint = self._setpoint
        if setpoint is None:
            return
        if now >= self._expires - EPS:
            self._setpoint = None  # the user stopped commanding: go quiet, let the watchdog act
            return
        if armed and now - self._sent >= self._options.keepalive - EPS:
            self._send(setpoint, now, keepalive=True)

    def deadline(self, t: float) -> float:
        """`t`, or earlier if a repeat or the expiry is due before it."""
        if self._setpoint is None:
            return t
        return min(t, self._sent + self._options.keepalive, self._expires)

    def _send(self, msg: SetWheelSpeeds | SetAckermann, now: float, keepalive: bool) -> int:
        seq = self._wire.send(msg, now)
        self._seq = seq
        self._sent = now
        self._n.setpoints_sent += 1
        if keepalive:
            self._n.keepalives_sent += 1
        return seq
