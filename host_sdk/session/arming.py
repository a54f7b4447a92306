"""Whether the board drives: armed, or in a latched FAILSAFE that the board reported or the host
predicted (it knows when it has gone quiet for a watchdog period)."""

from __future__ import annotations

from collections.abc import Callable

from host_sdk.errors import FailsafeError, NotArmedError
from host_sdk.failsafe import failsafe_meaning
from host_sdk.session.events import Event, FailsafeEntered
from protocol.generated.enums import FailsafeReason, Status

_FAILSAFE, _ARMED = int(Status.FAILSAFE), int(Status.ARMED)


class Arming:
    """Armed or not, and the latched failsafe (announced once, as a FailsafeEntered event)."""

    __slots__ = ("_armed", "_emit", "_failsafe", "_predicted")

    def __init__(self, emit: Callable[[Event], None]) -> None:
        self._emit = emit
        self._armed = False
        self._failsafe: FailsafeReason | None = None
        """Latched FAILSAFE the board reported (or the host predicted); None when not in failsafe."""
        self._predicted = False

    @property
    def armed(self) -> bool:
        return self._armed

    @property
    def failsafe(self) -> FailsafeReason | None:
        return self._failsafe

    def arm(self) -> None:
        """The board ACKed an ARM: armed, any failsafe cleared."""
        self._armed = True
        self._failsafe = None
        self._predicted = False

    def clear(self) -> None:
        """Disarmed with no failsafe (a DISARM, a new firmware session, or the end of the link)."""
        self._armed = False
        self._failsafe = None
        self._predicted = False

    def disarm(self) -> None:
        """Not armed; a latched failsafe stays."""
        self._armed = False

    def enter_failsafe(self, reason: FailsafeReason, predicted: bool) -> None:
        # A failsafe the host only predicted is announced again when the board confirms it.
        fresh = self._failsafe is None or self._predicted
        self._armed = False
        self._failsafe = reason
        self._predicted = predicted
        if fresh:
            self._emit(FailsafeEntered(reason, predicted))

    def predict_failsafe(self, quiet_s: float, watchdog_s: float) -> None:
        # Nothing sent for a watchdog period (plus two ticks) while armed: the board has failed
        # safe by now, whether or not its FEEDBACK saying so gets through (a cut cable).
        if self._armed and quiet_s > watchdog_s + 0.02:
            self.enter_failsafe(FailsafeReason.COMM_TIMEOUT, predicted=True)

    def board_status(self, status: int, reason: FailsafeReason) -> bool:
        """Follow FEEDBACK's status bits (plain ints: IntFlag operators are slow on this path).
        True when the board does not drive any more (the setpoint must go)."""
        if status & _FAILSAFE:
            self.enter_failsafe(reason, predicted=False)
            return True
        if status & _ARMED:
            if not self._armed and self._failsafe is None:
                self._armed = True  # an ARM whose ACK was lost was applied all the same
            return False
        if self._armed:
            self._armed = False
            return True
        return False

    def wants_rearm(self) -> bool:
        """Not armed, and nothing but a reset or a watchdog failsafe keeps it so (auto_rearm's cue)."""
        return not self._armed and self._failsafe in (None, FailsafeReason.COMM_TIMEOUT)

    def not_armed_error(self, reopening: bool, watchdog_s: float, command_timeout_s: float) -> NotArmedError:
        """The error for a drive command while not armed, saying why and what to do."""
        if self._failsafe is not None:
            hint = failsafe_meaning(self._failsafe)
            if self._failsafe is FailsafeReason.COMM_TIMEOUT:
                hint = (
                    f"no command reached the board for its {watchdog_s:g} s watchdog: the link was cut, or "
                    f"commands stopped (they expire {command_timeout_s:g} s after they are given, so renew "
                    "them in a loop); robot.arm() drives again"
                )
            return FailsafeError(self._failsafe, hint)
        if reopening:
            return NotArmedError("the session is re-opening after a reset; call robot.arm() when ready", "connecting")
        return NotArmedError("the robot is not armed: call robot.arm() first", "disarmed")
