# DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
# spec hash: 0xBDF31659
"""Session state machine table. Firmware session: one per boot; the host drives it with HELLO, ARM and DISARM and the watchdog ends it."""

from __future__ import annotations

import enum
from dataclasses import dataclass


class SessionState(enum.IntEnum):
    BOOT = 0
    """Hardware and config initialising; motors disabled."""
    IDLE = 1
    """Booted and announced; no session. Waits for a compatible HELLO."""
    DISARMED = 2
    """Session open; motors in safe state; reliable requests accepted."""
    ARMED = 3
    """Motors enabled; setpoints applied; the watchdog runs."""
    FAILSAFE = 4
    """Latched after a watchdog expiry or fault; motors in safe state until re-ARM or DISARM."""


class SessionEvent(enum.IntEnum):
    INIT_DONE = 0
    """Hardware and config are ready."""
    HELLO = 1
    """A HELLO frame arrived."""
    ARM = 2
    """An ARM frame arrived."""
    DISARM = 3
    """A DISARM frame arrived."""
    SETPOINT = 4
    """A setpoint frame arrived."""
    VALID_FRAME = 5
    """Any valid host frame arrived (before its own event)."""
    WATCHDOG_EXPIRED = 6
    """No valid host frame for the watchdog period (checked every control tick)."""
    FAULT = 7
    """The control loop found a fault (encoder, config, supply)."""
    RESET = 8
    """Reset request, brown-out or watchdog reset of the MCU."""


class Guard(enum.IntEnum):
    COMPATIBLE = 1
    """HELLO's protocol_version and spec_hash equal the firmware's."""
    BOOT_ID_MATCHES = 2
    """ARM's boot_id equals this boot's boot_id."""


class Action(enum.IntFlag):
    ANNOUNCE = 1 << 0
    """Send the boot IDENTITY (reason BOOT)."""
    ACCEPT_HELLO = 1 << 1
    """Apply the requested watchdog and feedback mode (clamped); answer IDENTITY(HELLO_ACCEPTED)."""
    REJECT_HELLO = 1 << 2
    """Answer IDENTITY(HELLO_REJECTED) so the host can report both hashes."""
    MOTORS_SAFE = 1 << 3
    """Put the motors in the configured safe state and the steering at centre; clear setpoints and integrators."""
    MOTORS_ENABLE = 1 << 4
    """Let the control loop drive the motors from setpoints."""
    FEED_WATCHDOG = 1 << 5
    """Restart the watchdog period."""
    LATCH_REASON = 1 << 6
    """Record the failsafe reason and report it in FEEDBACK."""
    CLEAR_REASON = 1 << 7
    """Clear the latched failsafe reason."""
    ACK = 1 << 8
    """Answer ACK with the request's id and seq."""
    NACK = 1 << 9
    """Answer NACK with the request's id and seq and the reason for this state."""
    APPLY_SETPOINT = 1 << 10
    """Store the setpoint: stream mode, the next control tick applies it (latest wins); lockstep, it joins the queue (LOCKSTEP_QUEUE), each tick applying the oldest."""


@dataclass(frozen=True, slots=True)
class Transition:
    """One row: in `source`, on `event`, if `guard` holds (is false when `negated`):
    go to `target` and do `actions`."""

    source: SessionState
    event: SessionEvent
    guard: Guard | None
    negated: bool
    target: SessionState
    actions: Action


INITIAL_STATE = SessionState.BOOT

TRANSITIONS: tuple[Transition, ...] = (
    Transition(SessionState.BOOT, SessionEvent.INIT_DONE, None, False, SessionState.IDLE, Action.MOTORS_SAFE | Action.ANNOUNCE),
    Transition(SessionState.IDLE, SessionEvent.HELLO, Guard.COMPATIBLE, False, SessionState.DISARMED, Action.ACCEPT_HELLO),
    Transition(SessionState.IDLE, SessionEvent.HELLO, Guard.COMPATIBLE, True, SessionState.IDLE, Action.REJECT_HELLO),
    Transition(SessionState.DISARMED, SessionEvent.HELLO, Guard.COMPATIBLE, False, SessionState.DISARMED, Action.MOTORS_SAFE | Action.CLEAR_REASON | Action.ACCEPT_HELLO),
    Transition(SessionState.ARMED, SessionEvent.HELLO, Guard.COMPATIBLE, False, SessionState.DISARMED, Action.MOTORS_SAFE | Action.CLEAR_REASON | Action.ACCEPT_HELLO),
    Transition(SessionState.FAILSAFE, SessionEvent.HELLO, Guard.COMPATIBLE, False, SessionState.DISARMED, Action.MOTORS_SAFE | Action.CLEAR_REASON | Action.ACCEPT_HELLO),
    Transition(SessionState.DISARMED, SessionEvent.HELLO, Guard.COMPATIBLE, True, SessionState.IDLE, Action.MOTORS_SAFE | Action.CLEAR_REASON | Action.REJECT_HELLO),
    Transition(SessionState.ARMED, SessionEvent.HELLO, Guard.COMPATIBLE, True, SessionState.IDLE, Action.MOTORS_SAFE | Action.CLEAR_REASON | Action.REJECT_HELLO),
    Transition(SessionState.FAILSAFE, SessionEvent.HELLO, Guard.COMPATIBLE, True, SessionState.IDLE, Action.MOTORS_SAFE | Action.CLEAR_REASON | Action.REJECT_HELLO),
    Transition(SessionState.IDLE, SessionEvent.ARM, None, False, SessionState.IDLE, Action.NACK),
    Transition(SessionState.DISARMED, SessionEvent.ARM, Guard.BOOT_ID_MATCHES, False, SessionState.ARMED, Action.CLEAR_REASON | Action.FEED_WATCHDOG | Action.MOTORS_ENABLE | Action.ACK),
    Transition(SessionState.FAILSAFE, SessionEvent.ARM, Guard.BOOT_ID_MATCHES, False, SessionState.ARMED, Action.CLEAR_REASON | Action.FEED_WATCHDOG | Action.MOTORS_ENABLE | Action.ACK),
    Transition(SessionState.ARMED, SessionEvent.ARM, Guard.BOOT_ID_MATCHES, False, SessionState.ARMED, Action.FEED_WATCHDOG | Action.ACK),
    Transition(SessionState.DISARMED, SessionEvent.ARM, Guard.BOOT_ID_MATCHES, True, SessionState.DISARMED, Action.NACK),
    Transition(SessionState.ARMED, SessionEvent.ARM, Guard.BOOT_ID_MATCHES, True, SessionState.ARMED, Action.NACK),
    Transition(SessionState.FAILSAFE, SessionEvent.ARM, Guard.BOOT_ID_MATCHES, True, SessionState.FAILSAFE, Action.NACK),
    Transition(SessionState.IDLE, SessionEvent.DISARM, None, False, SessionState.IDLE, Action.ACK),
    Transition(SessionState.DISARMED, SessionEvent.DISARM, None, False, SessionState.DISARMED, Action.MOTORS_SAFE | Action.CLEAR_REASON | Action.ACK),
    Transition(SessionState.ARMED, SessionEvent.DISARM, None, False, SessionState.DISARMED, Action.MOTORS_SAFE | Action.CLEAR_REASON | Action.ACK),
    Transition(SessionState.FAILSAFE, SessionEvent.DISARM, None, False, SessionState.DISARMED, Action.MOTORS_SAFE | Action.CLEAR_REASON | Action.ACK),
    Transition(SessionState.ARMED, SessionEvent.SETPOINT, None, False, SessionState.ARMED, Action.APPLY_SETPOINT),
    Transition(SessionState.IDLE, SessionEvent.SETPOINT, None, False, SessionState.IDLE, Action.NACK),
    Transition(SessionState.DISARMED, SessionEvent.SETPOINT, None, False, SessionState.DISARMED, Action.NACK),
    Transition(SessionState.FAILSAFE, SessionEvent.SETPOINT, None, False, SessionState.FAILSAFE, Action.NACK),
    Transition(SessionState.DISARMED, SessionEvent.VALID_FRAME, None, False, SessionState.DISARMED, Action.FEED_WATCHDOG),
    Transition(SessionState.ARMED, SessionEvent.VALID_FRAME, None, False, SessionState.ARMED, Action.FEED_WATCHDOG),
    Transition(SessionState.FAILSAFE, SessionEvent.VALID_FRAME, None, False, SessionState.FAILSAFE, Action.FEED_WATCHDOG),
    Transition(SessionState.ARMED, SessionEvent.WATCHDOG_EXPIRED, None, False, SessionState.FAILSAFE, Action.MOTORS_SAFE | Action.LATCH_REASON),
    Transition(SessionState.ARMED, SessionEvent.FAULT, None, False, SessionState.FAILSAFE, Action.MOTORS_SAFE | Action.LATCH_REASON),
    Transition(SessionState.DISARMED, SessionEvent.FAULT, None, False, SessionState.FAILSAFE, Action.MOTORS_SAFE | Action.LATCH_REASON),
    Transition(SessionState.BOOT, SessionEvent.RESET, None, False, SessionState.BOOT, Action.MOTORS_SAFE),
    Transition(SessionState.IDLE, SessionEvent.RESET, None, False, SessionState.BOOT, Action.MOTORS_SAFE),
    Transition(SessionState.DISARMED, SessionEvent.RESET, None, False, SessionState.BOOT, Action.MOTORS_SAFE),
    Transition(SessionState.ARMED, SessionEvent.RESET, None, False, SessionState.BOOT, Action.MOTORS_SAFE),
    Transition(SessionState.FAILSAFE, SessionEvent.RESET, None, False, SessionState.BOOT, Action.MOTORS_SAFE),
)
"""Rows in spec order; the first row matching (state, event) whose guard holds fires."""
