"""The session's options and its states (what every part of it reads, none of them changes)."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from protocol.generated.constants import FEEDBACK_HZ_DEFAULT, WATCHDOG_DEFAULT_MS
from protocol.generated.enums import FeedbackMode

EPS = 1e-6  # timers fire this early rather than a poll late (float time)


class LinkState(enum.Enum):
    """Where the host's side of the session is."""

    CONNECTING = "connecting"
    """Sending HELLO until an IDENTITY answers (first connect, or after a reset)."""
    OPEN = "open"
    """The board accepted our HELLO: requests and (once armed) setpoints flow."""
    INCOMPATIBLE = "incompatible"
    """The firmware speaks another protocol version or spec: nothing more is sent."""
    BROKEN = "broken"
    """The link under the session failed (the port vanished, the runner stopped): nothing more is sent."""
    CLOSED = "closed"


@dataclass(frozen=True, slots=True)
class SessionOptions:
    """Timing and mode of a session. Seconds everywhere."""

    watchdog_s: float = WATCHDOG_DEFAULT_MS / 1000
    feedback_mode: FeedbackMode = FeedbackMode.STREAM
    feedback_hz: int = FEEDBACK_HZ_DEFAULT
    """Requested stream rate; 0 asks for the board's configured default."""
    hello_interval_s: float = 0.1
    request_timeout_s: float = 0.25
    """Per try; SAVE_CONFIG gets `save_timeout_s` (EEPROM writes stall the board's loop)."""
    save_timeout_s: float = 1.5
    request_tries: int = 5
    command_timeout_s: float | None = None
    """How long a setpoint stays live without being renewed; None: watchdog_s / 2."""
    keepalive_s: float | None = None
    """How often a live setpoint is repeated; None: watchdog_s / 4."""
    ping_interval_s: float = 1.0
    paced: bool = False
    """Lockstep: the session sends the live setpoint once per feedback period, on the board's
    control-tick grid (setpoints.py), and a new command waits for the next slot."""
    auto_rearm: bool = False
    reset_silence_s: float = 2.0
    """How long a board stays silent when it is reset before it announces its new boot: the
    bootloader's time after a DTR or external reset (1.5 s on a Mega, 1 s on an Uno) and its setup,
    rounded up. A wait for the board that meets a silence younger than this waits it out, as it
    may end in a reset (docs/sdk.md, "Resets")."""
    url: str = ""
    baud: int = 0

    @property
    def command_timeout(self) -> float:
        return self.command_timeout_s if self.command_timeout_s is not None else self.watchdog_s / 2

    @property
    def keepalive(self) -> float:
        return self.keepalive_s if self.keepalive_s is not None else self.watchdog_s / 4
