"""Turn signals driven by motion state (robots with the TURN_SIGNALS capability).

The firmware derives the pattern from its own state each control tick:

| state | front left | front right | rear left | rear right |
|---|---|---|---|---|
| IDLE, DISARMED (BOOT) | off | off | off | off |
| FAILSAFE | blink | blink | blink | blink (hazard lights) |
| ARMED, turning left | blink | off | blink | reversing |
| ARMED, turning right | off | blink | reversing | blink |
| ARMED, straight | off | off | reversing | reversing |

"Turning" means the ramped wheel speeds differ by more than TURN_THRESHOLD_MM_S (right faster:
left turn); "reversing" means their mean is below -TURN_THRESHOLD_MM_S (rear lights on steadily).
Blinking is 1.5 Hz with a 50 % duty, phased on the tick counter.
"""

from __future__ import annotations

from emulator.firmware.board import LIGHT_FRONT_LEFT, LIGHT_FRONT_RIGHT, LIGHT_REAR_LEFT, LIGHT_REAR_RIGHT
from host_sdk.statemachine import SessionState

TURN_THRESHOLD_MM_S = 30.0
BLINK_PERIOD_TICKS = 66


def light_mask(state: SessionState, left_mm_s: float, right_mm_s: float, tick: int) -> int:
    blink_on = tick % BLINK_PERIOD_TICKS < BLINK_PERIOD_TICKS // 2
    if state is SessionState.FAILSAFE:
        return 0x0F if blink_on else 0
    if state is not SessionState.ARMED:
        return 0
    left_turn = right_mm_s - left_mm_s > TURN_THRESHOLD_MM_S
    right_turn = left_mm_s - right_mm_s > TURN_THRESHOLD_MM_S
    reversing = (left_mm_s + right_mm_s) / 2 < -TURN_THRESHOLD_MM_S
    mask = 0
    if left_turn:
        mask |= (LIGHT_FRONT_LEFT | LIGHT_REAR_LEFT) if blink_on else 0
    elif reversing:
        mask |= LIGHT_REAR_LEFT
    if right_turn:
        mask |= (LIGHT_FRONT_RIGHT | LIGHT_REAR_RIGHT) if blink_on else 0
    elif reversing:
        mask |= LIGHT_REAR_RIGHT
    return mask
