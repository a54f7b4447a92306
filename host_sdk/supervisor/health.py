"""What a supervised robot is doing, as a program shows it: the link, arming, the last board reset,
the failsafe, and the refusals a person must see (`Health`, one snapshot; `Health.banner()` the
one line that says what is wrong and what to do)."""

from __future__ import annotations

import time
from dataclasses import dataclass

from host_sdk.failsafe import failsafe_meaning
from protocol.generated.enums import FailsafeReason

LINK_UP, LINK_LOST, LINK_RECONNECTING, LINK_CLOSED = "up", "lost", "reconnecting", "closed"


def clock_time(wall: float) -> str:
    """A wall-clock time as the person beside the robot reads it (local, to the second)."""
    return time.strftime("%H:%M:%S", time.localtime(wall))


@dataclass(frozen=True, slots=True)
class BoardReset:
    """A board reset (a brown-out, the reset button, a watchdog reboot): when, and which boots."""

    at_s: float
    """On the robot's clock."""
    wall: float
    """`time.time()` then, for people."""
    old_boot_id: int
    new_boot_id: int | None

    def text(self) -> str:
        new = "?" if self.new_boot_id is None else f"0x{self.new_boot_id:08X}"
        return f"board reset at {clock_time(self.wall)} (boot_id 0x{self.old_boot_id:08X} -> {new})"


@dataclass(frozen=True, slots=True)
class Refusal:
    """A request the robot did not carry out (an ARM with no answer, one the board refused...):
    kept until the program or the person dismisses it (`Supervisor.dismiss(id)`)."""

    id: int
    what: str
    """The request: "ARM", "DISARM", "drive"."""
    text: str
    """The error, as it said it."""
    wall: float

    def line(self) -> str:
        said = self.text if self.text.startswith(f"{self.what}:") else f"{self.what}: {self.text}"
        return f"{clock_time(self.wall)} {said}"


@dataclass(frozen=True, slots=True)
class Banner:
    level: str
    """"error" (the robot cannot drive: link lost, port lost) or "warning" (failsafe, reset)."""
    text: str
    """What happened, since when."""
    hint: str
    """What to do."""


@dataclass(frozen=True, slots=True)
class Health:
    link: str
    """"up" (FEEDBACK arrives), "lost" (the board is silent: a cut cable, a hung or rebooting
    board), "reconnecting" (the port itself is gone and is being opened again) or "closed"."""
    since_s: float | None
    """When the link went down, on the robot's clock (None while it is up)."""
    since_wall: float | None
    now_s: float
    armed: bool
    """Armed as far as anyone can know: never while the link is down."""
    state: str
    """The robot's own word (`Robot.state`): disarmed, armed, failsafe, connecting, broken, closed."""
    failsafe: str | None
    """The latched failsafe's reason (COMM_TIMEOUT, LOW_VOLTAGE...), None when not in failsafe."""
    reset: BoardReset | None
    """The last board reset, until the robot is armed again."""
    refusals: tuple[Refusal, ...]
    busy: str | None
    """A request under way: "arming", "disarming"."""
    halts: int
    """How many times the robot stopped being armed and reachable (a failsafe, a reset, the link
    lost, a disarm): whatever drives by itself must stop each time this grows."""
    halt_why: str
    port_error: str
    """Why the port was lost, or why opening it again failed (while reconnecting)."""
    attempts: int
    """Failed attempts to open the port again since it was lost."""
    url: str

    @property
    def stale(self) -> bool:
        """What the board reports (pose, speeds, rates) is old: the link is down."""
        return self.link != LINK_UP

    def down_for_s(self) -> float:
        return 0.0 if self.since_s is None else max(0.0, self.now_s - self.since_s)

    def banner(self) -> Banner | None:
        """The one thing a person must know now (None: nothing is wrong)."""
        since = "" if self.since_wall is None else f" since {clock_time(self.since_wall)} ({self.down_for_s():.0f} s)"
        if self.link == LINK_RECONNECTING:
            tries = f" (attempt {self.attempts})" if self.attempts else ""
            return Banner(
                "error",
                f"port lost{since}: {self.port_error or self.url}",
                f"opening {self.url} again{tries}; then arm to drive",
            )
        if self.link == LINK_LOST and self.port_error:
            return Banner(
                "error",
                f"port lost{since}: {self.port_error}",
                "start the program again (Supervisor.connect opens a lost port again by itself)",
            )
        if self.link == LINK_LOST:
            hint = "driving stopped; it reconnects by itself when the board answers, then arm to drive"
            return Banner("error", f"link lost{since}: no answer from the board on {self.url}", hint)
        if self.link == LINK_CLOSED:
            return Banner("error", f"{self.url} is closed", "start the program again")
        if self.failsafe is not None:
            known = self.failsafe in FailsafeReason.__members__
            why = failsafe_meaning(FailsafeReason[self.failsafe]) if known else "the board stopped the motors"
            return Banner("warning", f"failsafe {self.failsafe}: {why}", "arm to drive again")
        if self.reset is not None and not self.armed:
            return Banner("warning", self.reset.text() + ": disarmed", "arm to drive again")
        return None
