"""The handshake: HELLO (with a GET_CONFIG right behind it, so one round trip gives both the
session and the configuration) every `hello_interval_s` until an IDENTITY answers one of them,
and what it learns of the board: its identity, and its configuration as last read or written.

A boot announcement is answered at once (ready follows boot by one round trip); a protocol version
or spec hash that differs fails closed (IncompatibleFirmwareError). receive.py decides what an
IDENTITY means; this part keeps the HELLOs it may answer.
"""

from __future__ import annotations

from host_sdk.errors import ConnectTimeoutError
from host_sdk.session.counters import HostCounters
from host_sdk.session.options import EPS, SessionOptions
from host_sdk.session.types import RobotIdentity
from host_sdk.session.wire import Wire
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH
from protocol.generated.enums import Capability, FeedbackMode
from protocol.generated.messages import Config, GetConfig, Hello, Identity, SetConfig

_HELLO_WATCHDOG = next(f for f in Hello.FIELDS if f.name == "watchdog_ms")
_HELLO_RATE = next(f for f in Hello.FIELDS if f.name == "feedback_hz")
CONFIG_FIELDS = tuple(f.name for f in SetConfig.FIELDS)


def config_of(msg: Config) -> SetConfig:
    return SetConfig(**{name: getattr(msg, name) for name in CONFIG_FIELDS})


def compatible(msg: Identity) -> bool:
    """The firmware speaks our protocol version and spec (else the session fails closed)."""
    return msg.protocol_version == PROTOCOL_VERSION and msg.spec_hash == SPEC_HASH


class Handshake:
    """The HELLOs in flight, and the board's identity and configuration."""

    def __init__(self, options: SessionOptions, wire: Wire, counters: HostCounters) -> None:
        self._options = options
        self._wire = wire
        self._n = counters
        self._next_hello = 0.0
        self._hello_seqs: dict[int, int] = {}  # HELLO seq -> the GET_CONFIG seq sent right behind it
        self._config_seqs: set[int] = set()
        self._identities_seen = 0
        self._opened_once = False
        self._identity: RobotIdentity | None = None
        self._config: SetConfig | None = None
        self._config_fresh = False
        self._ready_announced = False
        self._opened_s: float | None = None
        self._started_s: float | None = None
        self._ready_s: float | None = None

    # == HELLO =====================================================================================
    @property
    def next_hello(self) -> float:
        return self._next_hello

    def start(self, now: float) -> None:
        """The first HELLO is due now."""
        self._started_s = now
        self._next_hello = now

    def hello_due(self, now: float) -> bool:
        return now >= self._next_hello - EPS

    def send_hello(self, now: float) -> int:
        """Send HELLO and the GET_CONFIG behind it; returns the GET_CONFIG's seq."""
        o = self._options
        hello = Hello(
            protocol_version=PROTOCOL_VERSION,
            spec_hash=SPEC_HASH,
            watchdog_ms=max(int(_HELLO_WATCHDOG.lo), min(int(_HELLO_WATCHDOG.hi), round(o.watchdog_s * 1000))),
            feedback_mode=o.feedback_mode,
            feedback_hz=max(int(_HELLO_RATE.lo), min(int(_HELLO_RATE.hi), o.feedback_hz)),
        )
        hello_seq = self._wire.send(hello, now)
        config_seq = self._wire.send(GetConfig(), now)
        self._hello_seqs[hello_seq] = config_seq
        self._config_seqs.add(config_seq)
        if len(self._hello_seqs) > 32:
            oldest = next(iter(self._hello_seqs))
            self._config_seqs.discard(self._hello_seqs.pop(oldest))
        self._n.hellos_sent += 1
        self._next_hello = now + o.hello_interval_s
        return config_seq

    def restart(self, now: float) -> None:
        """The board's session is gone: forget the HELLOs sent, the next is due now."""
        self._hello_seqs.clear()
        self._config_seqs.clear()
        self._next_hello = now

    # == IDENTITY ==================================================================================
    def heard(self, msg: Identity) -> bool:
        """Count an IDENTITY; True when the firmware is compatible."""
        self._identities_seen += 1
        return compatible(msg)

    def sent_hello(self, hello_seq: int) -> bool:
        """`hello_seq` is one of our HELLOs still unanswered."""
        return hello_seq in self._hello_seqs

    def answered(self, hello_seq: int) -> bool:
        """An IDENTITY answers `hello_seq`: True when that was one of our HELLOs (now answered)."""
        return self._hello_seqs.pop(hello_seq, None) is not None

    def open(self, msg: Identity, now: float) -> bool:
        """The IDENTITY `msg` opened a session; the configuration is to be read again. True when
        this session replaces one that a reset ended."""
        reconnect = self._opened_once
        self._identity = RobotIdentity.of(msg, now)
        self._opened_s = now
        self._config_fresh = False
        self._ready_announced = False
        if reconnect:
            self._n.reconnects += 1
        self._opened_once = True
        return reconnect

    def reopened(self, msg: Identity, now: float) -> None:
        """The board re-opened the same boot's session (a HELLO of ours that crossed the first answer)."""
        self._identity = RobotIdentity.of(msg, now)

    # == CONFIG ====================================================================================
    def behind_hello(self, req_seq: int) -> bool:
        """`req_seq` is a GET_CONFIG sent behind a HELLO."""
        return req_seq in self._config_seqs

    def config_answered(self, msg: Config) -> None:
        """The CONFIG answering a GET_CONFIG behind a HELLO."""
        self._config_seqs.discard(msg.req_seq)
        self.config_read(msg)

    def config_read(self, msg: Config) -> None:
        self._config = config_of(msg)
        self._config_fresh = True

    def config_written(self, msg: SetConfig) -> None:
        self._config = msg

    def refresh_due(self, now: float) -> bool:
        """The GET_CONFIG behind the HELLO normally answers in the same round trip; True when the
        configuration has not come one request timeout after the session opened."""
        opened = self._opened_s
        return not self._config_fresh and opened is not None and now >= opened + self._options.request_timeout_s

    def announce_ready(self, now: float) -> bool:
        """True once per session, when identity and configuration are both known."""
        if not self._config_fresh or self._ready_announced:
            return False
        self._ready_announced = True
        if self._ready_s is None:
            self._ready_s = now
        return True

    # == what it knows (read-only) =================================================================
    @property
    def identity(self) -> RobotIdentity | None:
        return self._identity

    @property
    def config(self) -> SetConfig | None:
        return self._config

    @property
    def config_fresh(self) -> bool:
        """The configuration was read in this session."""
        return self._config_fresh

    @property
    def started_s(self) -> float | None:
        return self._started_s

    @property
    def ready_s(self) -> float | None:
        return self._ready_s

    @property
    def boot_id(self) -> int | None:
        return self._identity.boot_id if self._identity is not None else None

    @property
    def watchdog_s(self) -> float:
        if self._identity is not None and self._identity.watchdog_ms:
            return self._identity.watchdog_ms / 1000
        return self._options.watchdog_s

    @property
    def feedback_mode(self) -> FeedbackMode:
        return self._identity.feedback_mode if self._identity is not None else self._options.feedback_mode

    def connect_time_s(self) -> float | None:
        """From the first HELLO to the first ready."""
        if self._ready_s is None or self._started_s is None:
            return None
        return self._ready_s - self._started_s

    def esc_window_left(self, now: float) -> float:
        """Seconds until an ESC robot's power-up arming window ends (0 without an ESC)."""
        ident, config = self._identity, self._config
        if ident is None or config is None or not ident.capabilities & Capability.ESC:
            return 0.0
        uptime_s = ident.uptime_ms / 1000 + (now - ident.received_s)
        return max(0.0, config.esc_arm_ms / 1000 - uptime_s + 0.02)

    def connect_timeout_error(self, timeout_s: float) -> ConnectTimeoutError:
        """Why no session opened within `timeout_s`, from what was heard."""
        d = self._wire.decoder.stats
        o = self._options
        return ConnectTimeoutError(
            o.url,
            o.baud,
            timeout_s,
            bytes_received=d.bytes_received,
            frames_ok=d.frames_ok,
            identity_seen=self._identities_seen > 0,
        )
