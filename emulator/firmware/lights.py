"""Turn signals driven by motion state (robots with the TURN_SIGNALS capability).

The same patterns as the C++ core (docs/firmware.md, "Lights"), from the wheel targets in effect
and a blink counter that runs over BLINK_PERIOD_TICKS (66 ticks: 1.5 Hz, half on) from boot:

| state / motion | pattern |
|---|---|
| BOOT, IDLE, DISARMED | front pair and rear pair alternate at 1.5 Hz |
| ARMED, turning left: right - left > max(abs(left), abs(right)) / 8 | left pair blinks at 1.5 Hz |
| ARMED, turning right | right pair blinks at 1.5 Hz |
| ARMED, rotating in place (targets of opposite signs) | all four blink at 1.5 Hz |
| ARMED, straight or stopped | off |
| ARMED, Ackermann | left or right pair from the sign of the steering angle |
| FAILSAFE | all four blink fast, 3 Hz |
"""

from __future__ import annotations

from emulator.firmware.statemachine import SessionState
from protocol.generated.hardware import Lights

BLINK_PERIOD_TICKS = 66
LEFT = int(Lights.FRONT_LEFT | Lights.REAR_LEFT)
RIGHT = int(Lights.FRONT_RIGHT | Lights.REAR_RIGHT)
FRONT = int(Lights.FRONT_LEFT | Lights.FRONT_RIGHT)
REAR = int(Lights.REAR_LEFT | Lights.REAR_RIGHT)
ALL = LEFT | RIGHT


def light_mask(state: SessionState, left: int, right: int, *, steer_cdeg: int, ackermann: bool, blink: int) -> int:
    on = blink < BLINK_PERIOD_TICKS // 2
    if state is SessionState.FAILSAFE:
        return ALL if blink % (BLINK_PERIOD_TICKS // 2) < BLINK_PERIOD_TICKS // 4 else 0
    if state is not SessionState.ARMED:
        return FRONT if on else REAR
    if not on:
        return 0
    if ackermann:
        return LEFT if steer_cdeg > 0 else RIGHT if steer_cdeg < 0 else 0
    if (left > 0 > right) or (left < 0 < right):
        return ALL  # rotating in place
    magnitude = max(abs(left), abs(right))
    turn = right - left  # > 0: the heading turns counter-clockwise (left)
    if turn * 8 > magnitude:
        return LEFT
    if -turn * 8 > magnitude:
        return RIGHT
    return 0
