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
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass

from host_sdk import Ackermann, Robot, RoverLinkError
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
ZERO_HOLD_S = 0.5
"""How long a zero command stays live in the SDK (renewed by every tick while armed)."""
DRIVE_HOLD_MAX_S = 0.6
"""A driving command lives at most this long in the SDK, whatever `key_timeout_s`: how long a hung
teleop keeps the robot going (then the board's watchdog)."""
TICK_HZ = 20.0
"""How often the controller's thread sends the current command."""
HELP = "arrows/WASD drive (hold)  +/- speed  space stop  enter/r arm  x disarm  q quit"


@dataclass
class _Held:
    value: int = 0
    until: float = 0.0


class TeleopController:
    """Turns keys into drive commands; `tick()` sends the current one: `start()` calls it at
    TICK_HZ from a thread of its own, or call it yourself at about that rate."""

    def __init__(self, robot: Robot, *, key_timeout_s: float = 0.6, level: int = 1) -> None:
        self.robot = robot
        self.key_timeout_s = key_timeout_s
        self.level = level
        self.ackermann = not robot.identity.capabilities & Capability.DIFF_DRIVE
        self._linear = _Held()
        self._turn = _Held()
        self.message = HELP
        self.setpoint: Setpoint | None = None
        self._busy = threading.Lock()
        self._ticking = threading.Event()
        self._ticker: threading.Thread | None = None

    @property
    def speed_m_s(self) -> float:
        return self.robot.config.max_wheel_speed_mm_s / 1000 * LEVELS[self.level]

    def key(self, name: str) -> str | None:
        """Handle a key (Textual's key names); returns the action, or None for other keys."""
        action = KEYS.get(name)
        now = self.robot.now()
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
        """Send the current target (zero once the keys stopped); nothing while disarmed."""
        if not self.robot.armed or not self._busy.acquire(blocking=False):
            return
        try:
            now = self.robot.now()
            v, turn = self.target(now)
            hold = self.hold_s(now)
            if self.ackermann:
                kin = self.robot.kinematics
                steer = max(-math.pi / 2, min(math.pi / 2, turn))
                self.robot.drive_ackermann(v, steer, clamp=True, hold_s=hold)
                wheelbase = kin.wheelbase_m if isinstance(kin, Ackermann) else 1.0
                self.setpoint = Setpoint((v,), v, v * math.tan(steer) / wheelbase)
            else:
                self.robot.drive(v, turn, clamp=True, hold_s=hold)
                kin = self.robot.kinematics
                half = turn * getattr(kin, "track_m", 0.2) / 2
                self.setpoint = Setpoint((v - half, v + half), v, turn)
        except RoverLinkError as exc:
            self.message = f"error: {exc} (enter/r re-arms)"
        finally:
            self._busy.release()
