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

That is the AUTO mode. SET_LIGHTS chooses OFF (all dark) or MANUAL (each lamp steady, slow at
1.5 Hz or fast at 3 Hz, on the same blink counter: `host_mask`); FAILSAFE's fast blink shows in
every mode.
"""

from __future__ import annotations

from emulator.firmware.statemachine import SessionState
from protocol.generated.enums import LightsMode
from protocol.generated.hardware import Lights
from protocol.generated.messages import SetLights

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


def host_mask(setting: SetLights, blink: int) -> int:
    """The lamps SET_LIGHTS asks for outside AUTO: none in OFF, the masks' patterns in MANUAL."""
    if setting.mode is not LightsMode.MANUAL:
        return 0
    half = BLINK_PERIOD_TICKS // 2
    mask = setting.steady
    if blink < half:
        mask |= setting.slow
    if blink % half < BLINK_PERIOD_TICKS // 4:
        mask |= setting.fast
    return mask


def lights_now(
    state: SessionState, setting: SetLights, left: int, right: int, *, steer_cdeg: int, ackermann: bool, blink: int
) -> int:
    """The lamps lit this tick: AUTO (and FAILSAFE in every mode) from the motion state, else the host's."""
    if setting.mode is not LightsMode.AUTO and state is not SessionState.FAILSAFE:
        return host_mask(setting, blink)
    return light_mask(state, left, right, steer_cdeg=steer_cdeg, ackermann=ackermann, blink=blink)


def power_up(mode: LightsMode) -> SetLights:
    """The setting at boot and at each accepted HELLO: the robot's mode, no lamps in the masks."""
    return SetLights(mode=mode, steady=0, slow=0, fast=0)
