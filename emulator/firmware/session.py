"""The session state machine, driven only by the generated table (emulator.firmware.statemachine.step).

No transition is written by hand: `fire()` asks the table for the row that fires and returns it;
the firmware then performs the row's actions, in ACTION_ORDER (state changes before answers).
"""

from __future__ import annotations

from collections.abc import Callable

from emulator.firmware.statemachine import INITIAL_STATE, Action, Guard, SessionEvent, SessionState, Transition, step

ACTION_ORDER: tuple[Action, ...] = (
    Action.MOTORS_SAFE,
    Action.CLEAR_REASON,
    Action.LATCH_REASON,
    Action.FEED_WATCHDOG,
    Action.MOTORS_ENABLE,
    Action.APPLY_SETPOINT,
    Action.ACCEPT_HELLO,
    Action.REJECT_HELLO,
    Action.ANNOUNCE,
    Action.ACK,
    Action.NACK,
)
"""Order the firmware performs a row's actions in: state first, then the answer to the host."""

assert set(ACTION_ORDER) == set(Action), "every action of the generated table needs a place in ACTION_ORDER"


class Session:
    def __init__(self) -> None:
        self.state = INITIAL_STATE
        self.history: list[tuple[SessionState, SessionEvent, SessionState]] = []
        """Transitions that fired, oldest first (capped): for tests and the ground truth."""

    def fire(self, event: SessionEvent, guard: Callable[[Guard], bool] | None = None) -> Transition | None:
        """Run `event` through the table; the row that fired (state already updated) or None."""
        row = step(self.state, event, guard or _no_guard)
        if row is not None:
            if row.target != self.state or event not in (SessionEvent.VALID_FRAME, SessionEvent.SETPOINT):
                self.history.append((self.state, event, row.target))
                if len(self.history) > 1000:
                    del self.history[:500]
            self.state = row.target
        return row

    @property
    def open(self) -> bool:
        return self.state in (SessionState.DISARMED, SessionState.ARMED, SessionState.FAILSAFE)


def _no_guard(guard: Guard) -> bool:
    raise AssertionError(f"guard {guard.name} needs a value for this event")
