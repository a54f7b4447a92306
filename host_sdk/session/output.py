"""The session's sending half: frames out (numbered, counted), HELLO, PING, setpoint repeats, and
the host's own failsafe prediction (it knows when it has gone quiet)."""

from __future__ import annotations

from host_sdk.framing import encode_frame
from host_sdk.session.events import FailsafeEntered
from host_sdk.session.state import SessionState
from protocol.codec.message import Message
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH
from protocol.generated.enums import FailsafeReason
from protocol.generated.messages import GetConfig, Hello, Ping

EPS = 1e-6  # timers fire this early rather than a poll late (float time)
_HELLO_WATCHDOG = next(f for f in Hello.FIELDS if f.name == "watchdog_ms")
_HELLO_RATE = next(f for f in Hello.FIELDS if f.name == "feedback_hz")


class Output(SessionState):
    """Everything the session sends goes through `_send`."""

    # == sending ===================================================================================
    def _send(self, msg: Message, now: float, seq: int | None = None) -> int:
        if seq is None:
            seq = self._tx_seq
            self._tx_seq = (self._tx_seq + 1) & 0xFF
        wire = encode_frame(msg, seq)
        self._out.append(wire)
        self._n.frames_sent += 1
        self._n.bytes_sent += len(wire)
        self._last_tx = now
        return seq

    def _send_hello(self, now: float) -> None:
        o = self.options
        hello = Hello(
            protocol_version=PROTOCOL_VERSION,
            spec_hash=SPEC_HASH,
            watchdog_ms=max(int(_HELLO_WATCHDOG.lo), min(int(_HELLO_WATCHDOG.hi), round(o.watchdog_s * 1000))),
            feedback_mode=o.feedback_mode,
            feedback_hz=max(int(_HELLO_RATE.lo), min(int(_HELLO_RATE.hi), o.feedback_hz)),
        )
        hello_seq = self._send(hello, now)
        config_seq = self._send(GetConfig(), now)
        self._last_reliable_key = (GetConfig.MSG_ID, config_seq)
        self._hello_seqs[hello_seq] = config_seq
        self._handshake_config_seqs.add(config_seq)
        if len(self._hello_seqs) > 32:
            oldest = next(iter(self._hello_seqs))
            self._handshake_config_seqs.discard(self._hello_seqs.pop(oldest))
        self._n.hellos_sent += 1
        self._next_hello = now + o.hello_interval_s

    def _send_ping(self, now: float) -> None:
        stamp = round(now * 1e6) & 0xFFFFFFFF
        self._pings[stamp] = now
        if len(self._pings) > 16:
            del self._pings[next(iter(self._pings))]
        self._send(Ping(host_time_us=stamp), now)
        self._n.pings_sent += 1
        early = self.clock.samples < 8
        self._next_ping = now + (min(0.2, self.options.ping_interval_s) if early else self.options.ping_interval_s)

    def _send_setpoint(self, now: float, keepalive: bool) -> int:
        assert self._setpoint is not None
        seq = self._send(self._setpoint, now)
        self._setpoint_seq = seq
        self._setpoint_sent = now
        self._n.setpoints_sent += 1
        if keepalive:
            self._n.keepalives_sent += 1
        return seq

    def _keepalive(self, now: float) -> None:
        if self._setpoint is None:
            return
        if now >= self._setpoint_expires - EPS:
            self._setpoint = None  # the user stopped commanding: go quiet, let the watchdog act
            return
        if self._armed and now - self._setpoint_sent >= self.options.keepalive - EPS:
            self._send_setpoint(now, keepalive=True)

    def _quiet(self, now: float) -> bool:
        """Armed with no live command: send nothing that would feed the board's watchdog."""
        return self._armed and self._setpoint is None

    def _predict_failsafe(self, now: float) -> None:
        # Nothing sent for a watchdog period (plus two ticks) while armed: the board has failed
        # safe by now, whether or not its FEEDBACK saying so gets through (lockstep sends none).
        if self._armed and now - self._last_tx > self.watchdog_s + 0.02:
            self._armed = False
            self._failsafe = FailsafeReason.COMM_TIMEOUT
            self._failsafe_predicted = True
            self._events.append(FailsafeEntered(FailsafeReason.COMM_TIMEOUT, predicted=True))
