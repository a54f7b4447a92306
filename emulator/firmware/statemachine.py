"""Runs the generated session state-machine table (the firmware's rules, shared with the emulator).

>>> from emulator.firmware.statemachine import SessionEvent, SessionState, step
>>> row = step(SessionState.IDLE, SessionEvent.HELLO, lambda guard: True)
>>> row.target.name, row.actions
('DISARMED', <Action.ACCEPT_HELLO: 2>)
"""

from __future__ import annotations

from collections.abc import Callable

from protocol.generated.state_machine import (
    INITIAL_STATE,
    TRANSITIONS,
    Action,
    Guard,
    SessionEvent,
    SessionState,
    Transition,
)

__all__ = ["INITIAL_STATE", "TRANSITIONS", "Action", "Guard", "SessionEvent", "SessionState", "Transition", "step"]

_ROWS: dict[tuple[SessionState, SessionEvent], tuple[Transition, ...]] = {}
for _row in TRANSITIONS:
    _ROWS[_row.source, _row.event] = (*_ROWS.get((_row.source, _row.event), ()), _row)


def step(state: SessionState, event: SessionEvent, guard: Callable[[Guard], bool]) -> Transition | None:
    """The row that fires for `event` in `state`, or None (stay, do nothing).

    Rows are tried in spec order; `guard(g)` is called only for rows that have a guard.
    """
    for row in _ROWS.get((state, event), ()):
        if row.guard is None or guard(row.guard) != row.negated:
            return row
    return None
