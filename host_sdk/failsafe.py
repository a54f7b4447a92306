"""What each latched FAILSAFE reason means, in words a person at the robot can act on.

    describe_failsafe(robot.failsafe)   # 'ENCODER_FAULT: a wheel did not turn under effort: ...'

The board reports a reason code, not a diagnosis: ENCODER_FAULT is latched when a wheel is driven
hard and its encoder does not count, which is what a blocked wheel (the robot pushing against
something) and an unplugged encoder both look like. The text says both, so a bump is not read as
broken hardware; a program that has a lidar scan can say which it was
(`host_sdk.autonomy.guard.explain_failsafe`).
"""

from __future__ import annotations

from protocol.generated.enums import FailsafeReason

FAILSAFE_TEXT: dict[FailsafeReason, str] = {
    FailsafeReason.COMM_TIMEOUT: "no valid frame from the host reached the board for its watchdog period",
    FailsafeReason.ENCODER_FAULT: "a wheel did not turn under effort: blocked, or its encoder unplugged",
    FailsafeReason.BAD_CONFIG: "the board's configuration is inconsistent",
    FailsafeReason.LOW_VOLTAGE: "the supply is below its limit (charge or change the battery)",
}


def failsafe_meaning(reason: FailsafeReason) -> str:
    """What `reason` means, without its name ('see the firmware docs' for one this SDK has no words for)."""
    return FAILSAFE_TEXT.get(reason, "see the firmware docs")


def describe_failsafe(reason: FailsafeReason) -> str:
    """`NAME: what it means`."""
    return f"{reason.name}: {failsafe_meaning(reason)}"
