"""Keyboard driving, without the terminal: what each key does and when commands expire.

A terminal sends no key-release, only repeats while a key is held (after an initial delay of up
to half a second). So a direction key drives while its repeats keep arriving: each press renews
that direction for `key_timeout_s`; when they stop, the target falls back to zero and the robot
stops (the controller keeps sending zero, so the robot stays armed). Each command stays live in
the SDK only as long as the keys behind it (zero: ZERO_HOLD_S), so a busy UI that misses a few ticks
does not fail the robot safe, while a program that stops commanding still does: the SDK's command
expiry, then the board's watchdog. The commands go out from the controller's own thread (`start`),
not from the UI's event loop: a render or a slow terminal never delays the zero that follows a
released key.

Limits and kinematics are the SDK's: speeds are fractions of the board's max_wheel_speed_mm_s,
`drive(..., clamp=True)` keeps a differential-drive turn's curvature, Ackermann steering goes
to the servo's configured travel.

With a lidar (`guard`: host_sdk.autonomy.LidarGuard) every command goes through the avoider's
obstacle guard: it slows and stops short of what the lidar sees on its path. The override is held,
as the keys are: Shift with an arrow key drives without the guard while its repeats arrive; the
plain key (Shift let go) has the guard back at once.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass

from host_sdk import Ackermann, Robot, RoverLinkError
from host_sdk.autonomy.guard import Guarded, GuardState, LidarGuard
from host_sdk.enums import Capability
from host_sdk.profiles import steering_limits
from roverlink.dashboard import Setpoint

LEVELS = (0.1, 0.2, 0.35, 0.5, 0.75, 1.0)
KEYS = {
    "up": "forward",
    "w": "forward",
    "down": "back",
    "s": "back",
    "left": "left",
    "a": "left",
    "right": "right",
    "d": "right",
    "space": "stop",
    "plus": "faster",
    "equals_sign": "faster",
    "+": "faster",
    "=": "faster",
    "minus": "slower",
    "-": "slower",
    "enter": "arm",
    "r": "arm",
    "x": "disarm",
}
OVERRIDE_KEYS = {"shift+up": "forward", "shift+down": "back", "shift+left": "left", "shift+right": "right"}
"""An arrow with Shift held: driven without the obstacle guard. Not Shift with W A S D: a terminal
sends the same capital letter for Caps Lock, which would latch the override."""
ZERO_HOLD_S = 0.5
"""How long a zero command stays live in the SDK (renewed by every tick while armed)."""
DRIVE_HOLD_MAX_S = 0.6
"""A driving command lives at most this long in the SDK, whatever `key_timeout_s`: how long a hung
teleop keeps the robot going (then the board's watchdog)."""
TICK_HZ = 20.0
"""How often the controller's thread sends the current command."""
HELP = "arrows/WASD drive (hold)  +/- speed  space stop  enter/r arm  x disarm  q quit"
GUARDED_HELP = HELP.replace("(hold)", "(hold; Shift+arrows: no obstacle stop)")


@dataclass
class _Held:
    value: int = 0
    until: float = 0.0


class TeleopController:
    """Turns keys into drive commands; `tick()` sends the current one: `start()` calls it at
    TICK_HZ from a thread of its own, or call it yourself at about that rate."""

    def __init__(
        self, robot: Robot, *, key_timeout_s: float = 0.6, level: int = 1, guard: LidarGuard | None = None
    ) -> None:
        self.robot = robot
        self.key_timeout_s = key_timeout_s
        self.level = level
        self.ackermann = not robot.identity.capabilities & Capability.DIFF_DRIVE
        self.guard = guard
        """The obstacle guard on the lidar (None: no lidar, no protection)."""
        self._linear = _Held()
        self._turn = _Held()
        self._override = _Held()
        self.message = HELP if guard is None else GUARDED_HELP
        self.setpoint: Setpoint | None = None
        self.guarded: Guarded | None = None
        """The guard's verdict on the last command sent."""
        self._busy = threading.Lock()
        self._ticking = threading.Event()
        self._ticker: threading.Thread | None = None

    @property
    def speed_m_s(self) -> float:
        return self.robot.config.max_wheel_speed_mm_s / 1000 * LEVELS[self.level]

    def key(self, name: str) -> str | None:
        """Handle a key (Textual's key names); returns the action, or None for other keys."""
        action = KEYS.get(name) or OVERRIDE_KEYS.get(name)
        now = self.robot.now()
        if action in ("forward", "back", "left", "right"):  # Shift held with it, or let go
            self._override = _Held(1, now + self.key_timeout_s) if name in OVERRIDE_KEYS else _Held()
        if action == "forward":
            self._linear = _Held(1, now + self.key_timeout_s)
        elif action == "back":
            self._linear = _Held(-1, now + self.key_timeout_s)
        elif action == "left":
            self._turn = _Held(1, now + self.key_timeout_s)
        elif action == "right":
            self._turn = _Held(-1, now + self.key_timeout_s)
        elif action == "stop":
            self._linear = _Held()
            self._turn = _Held()
            self.robot.stop()
            self.message = "stopped"
        elif action in ("faster", "slower"):
            step = 1 if action == "faster" else -1
            self.level = max(0, min(len(LEVELS) - 1, self.level + step))
            self.message = f"speed {self.speed_m_s:.2f} m/s ({LEVELS[self.level] * 100:.0f} % of the limit)"
        elif action == "arm":
            # Off the UI's thread: an ESC robot's arming waits out the ESC's power-up window.
            self.message = "arming..."
            threading.Thread(target=self.arm, name="teleop arm", daemon=True).start()
        elif action == "disarm":
            self._linear = _Held()
            self._turn = _Held()
            self._guarded(self.robot.disarm, "disarmed")
        return action

    def arm(self) -> None:
        self._guarded(self.robot.arm, "armed: hold an arrow key to drive")

    def _guarded(self, call: object, done: str) -> None:
        try:
            call()  # type: ignore[operator]
            self.message = done
        except RoverLinkError as exc:
            self.message = f"error: {exc}"

    @property
    def status(self) -> str:
        """The message, and what the guard did to the command when it changed it."""
        g = self.guarded
        return self.message if g is None or g.state is GuardState.CLEAR else f"{self.message}  |  {g.text}"

    def override(self, now: float) -> bool:
        """Shift is held with the direction keys (their repeats are arriving)."""
        return self._override.value == 1 and now < self._override.until

    def target(self, now: float) -> tuple[float, float]:
        """(linear m/s, turn: rad/s for differential drive, steering rad for Ackermann)."""
        linear = self._linear.value if now < self._linear.until else 0
        turn = self._turn.value if now < self._turn.until else 0
        v = linear * self.speed_m_s
        if self.ackermann:
            right, left = steering_limits(self.robot.config)
            steer = left if turn > 0 else -right if turn < 0 else 0.0
            return v, steer
        kin = self.robot.kinematics
        track = getattr(kin, "track_m", 0.2)
        w = turn * 2 * self.speed_m_s / track
        return v, w

    def hold_s(self, now: float) -> float:
        """How long the current target stays what it is: until the first held key lapses (at most
        DRIVE_HOLD_MAX_S)."""
        held = [h.until - now for h in (self._linear, self._turn) if h.value and h.until > now]
        return max(min(*held, DRIVE_HOLD_MAX_S), 1e-3) if held else ZERO_HOLD_S

    def start(self) -> None:
        """Send the current command every 1/TICK_HZ from a thread of the controller's own
        (the robot's real clock), until `close()`."""
        if self._ticker is not None:
            return
        self._ticking.clear()
        self._ticker = threading.Thread(target=self._run, name="teleop ticker", daemon=True)
        self._ticker.start()

    def close(self) -> None:
        """Stop the thread `start()` began (the last command then expires as any other)."""
        self._ticking.set()
        if self._ticker is not None:
            self._ticker.join()
            self._ticker = None

    def _run(self) -> None:
        while not self._ticking.wait(1 / TICK_HZ):
            self.tick()

    def tick(self) -> None:
        """Send the current target (zero once the keys stopped); nothing while disarmed (the lidar is
        read all the same, so the guard's picture is current when the robot is armed)."""
        if not self._busy.acquire(blocking=False):
            return
        try:
            if not self.robot.armed:
                if self.guard is not None:
                    self.guard.poll()
                return
            now = self.robot.now()
            v, turn = self.target(now)
            hold = self.hold_s(now)
            if self.ackermann:
                kin = self.robot.kinematics
                steer = max(-math.pi / 2, min(math.pi / 2, turn))
                wheelbase = kin.wheelbase_m if isinstance(kin, Ackermann) else 1.0
                v = self._through_guard(v, v * math.tan(steer) / wheelbase, now)[0]  # the guard keeps the steering
                self.robot.drive_ackermann(v, steer, clamp=True, hold_s=hold)
                self.setpoint = Setpoint((v,), v, v * math.tan(steer) / wheelbase)
            else:
                v, turn = self._through_guard(v, turn, now)
                self.robot.drive(v, turn, clamp=True, hold_s=hold)
                kin = self.robot.kinematics
                half = turn * getattr(kin, "track_m", 0.2) / 2
                self.setpoint = Setpoint((v - half, v + half), v, turn)
        except RoverLinkError as exc:
            self.message = f"error: {exc} (enter/r re-arms)"
        finally:
            self._busy.release()

    def _through_guard(self, linear: float, angular: float, now: float) -> tuple[float, float]:
        """The body twist as the obstacle guard lets it go (as asked without a guard)."""
        if self.guard is None:
            return linear, angular
        self.guarded = self.guard.check(linear, angular, override=self.override(now))
        return self.guarded.linear_m_s, self.guarded.angular_rad_s
