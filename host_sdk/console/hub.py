"""What the robot program and the console's server exchange, across their two threads.

The program (its control loop) `show`s what it sees each period: the newest camera frame with the
track on it, the scan, the pose, its status. The server reads the newest of each when a browser is
ready for more; nothing queues, so a slow browser skips frames rather than falling behind. The
server `post`s what the driving browser asks for; the program `take`s it each period. A drive
command carries its time and lapses after `command_lifetime_s`, as every drive command does: a
closed or frozen tab stops the robot. So does following: it lasts while the driving browser's
keep-alive (`alive`, at least every third of the lifetime, and every command it sends) is
younger than one lifetime, unless the program runs `autonomous` (said at its start and on the page).
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

Image = NDArray[np.uint8]
Box = tuple[float, float, float, float]


@dataclass(frozen=True, slots=True)
class Frame:
    """A camera frame as the console shows it: an id (the page names the frame a box was drawn on
    by it), the robot program's time and the pixels."""

    id: int
    time_s: float
    image: Image
    jpeg: bytes | None = None
    """The camera's own JPEG of it, if it sent one (an MJPEG stream): forwarded as it is."""
    device_time_s: float | None = None
    """The capture time the camera carried (`CameraFrame.device_time_s`)."""


@dataclass(frozen=True, slots=True)
class Drive:
    linear_m_s: float
    angular_rad_s: float
    received_s: float
    """When the server got it (monotonic clock)."""
    override: bool = False
    """The user holds the override: driven as asked, without the obstacle protection."""


@dataclass(frozen=True, slots=True)
class Select:
    """A box drawn on frame `frame` (which the program still holds: `Hub.frame`)."""

    frame: Frame
    box: Box


@dataclass(slots=True)
class Requests:
    """What the browser asked for since the program last looked (`Hub.take`)."""

    drive: Drive | None = None
    select: Select | None = None
    follow: bool | None = None
    """Start (True) or stop (False) following."""
    arm: bool | None = None
    """Arm (True) or disarm (False)."""
    target_kind: str | None = None
    driver_alive: bool = True
    """The driving browser's keep-alive is fresh (or the console runs autonomous): following may go on."""


@dataclass(slots=True)
class _Shown:
    frame: Frame | None = None
    overlay: dict[str, Any] = field(default_factory=dict)
    state: dict[str, Any] = field(default_factory=dict)
    changed: dict[str, int] = field(default_factory=dict)
    """Each state key's version when last shown: a page is sent only what changed since it looked."""
    version: int = 0


class Hub:
    """The exchange. `clock` is the monotonic clock drive commands are stamped and aged with."""

    def __init__(
        self,
        *,
        keep_frames: int = 60,
        command_lifetime_s: float = 0.25,
        clock: Callable[[], float] = time.monotonic,
        autonomous: bool = False,
    ) -> None:
        self.command_lifetime_s = command_lifetime_s
        self.autonomous = autonomous
        """Following goes on with no browser keeping it alive (the user asked for it explicitly)."""
        self._alive_s = -float("inf")
        self.keep_frames = keep_frames
        self.clock = clock
        self._lock = threading.Lock()
        self._frames: deque[Frame] = deque(maxlen=keep_frames)
        self._next_id = 1
        self._shown = _Shown()
        self._requests = Requests()
        self._listeners: list[Callable[[], None]] = []

    # -- the program's side -------------------------------------------------------------------------
    def show_frame(
        self,
        image: Image,
        time_s: float,
        overlay: dict[str, Any] | None = None,
        *,
        jpeg: bytes | None = None,
        device_time_s: float | None = None,
    ) -> Frame:
        """A new camera frame and what to draw on it (the track's box, state, confidence)."""
        with self._lock:
            frame = Frame(self._next_id, time_s, image, jpeg, device_time_s)
            self._next_id += 1
            self._frames.append(frame)
            self._shown.frame = frame
            self._shown.overlay = dict(overlay or {})
            self._shown.version += 1
        self._notify()
        return frame

    def show_state(self, **state: Any) -> None:
        """Pose, scan, status...: JSON-able values, merged into what the page shows."""
        with self._lock:
            shown = self._shown
            shown.version += 1
            shown.state.update(state)
            shown.changed.update(dict.fromkeys(state, shown.version))
        self._notify()

    def take(self) -> Requests:
        """The requests since the last call (a drive command is kept until it lapses or is replaced)."""
        with self._lock:
            taken, self._requests = self._requests, Requests(drive=self._requests.drive)
            alive_s = self._alive_s
        now = self.clock()
        if taken.drive is not None and now - taken.drive.received_s > self.command_lifetime_s:
            taken.drive = None
        taken.driver_alive = self.autonomous or now - alive_s <= self.command_lifetime_s
        return taken

    # -- the server's side --------------------------------------------------------------------------
    def latest(self, since: int = -1) -> tuple[int, Frame | None, dict[str, Any], dict[str, Any]]:
        """(version, frame, its overlay, state): the newest of each; of the state, only the keys
        shown after version `since` (all of it by default)."""
        with self._lock:
            s = self._shown
            state = {k: v for k, v in s.state.items() if s.changed[k] > since}
            return s.version, s.frame, dict(s.overlay), state

    @property
    def version(self) -> int:
        """Grows whenever something new is shown."""
        with self._lock:
            return self._shown.version

    @property
    def frame_id(self) -> int:
        """The newest frame's id (0: none yet)."""
        with self._lock:
            return 0 if self._shown.frame is None else self._shown.frame.id

    def frame(self, frame_id: int) -> Frame | None:
        """A recent frame by id (None once it is older than the last `keep_frames`)."""
        with self._lock:
            return next((f for f in self._frames if f.id == frame_id), None)

    def post(self, **request: Any) -> None:
        """Record a request from the driving browser (`Requests`' fields)."""
        with self._lock:
            for name, value in request.items():
                setattr(self._requests, name, value)

    def alive(self) -> None:
        """The driving browser is there (its keep-alive, or any command it sent)."""
        with self._lock:
            self._alive_s = self.clock()

    @property
    def alive_s(self) -> float:
        """When the driving browser was last heard (`clock`; -inf: no driver)."""
        with self._lock:
            return self._alive_s

    def stop_driving(self) -> None:
        """Forget the drive command and the keep-alive at once (the driving browser left)."""
        with self._lock:
            self._requests.drive = None
            self._alive_s = -float("inf")

    def stop(self) -> None:
        """STOP: no drive command and no following (arming again does not drive off by itself)."""
        with self._lock:
            self._requests.drive = None
            self._requests.follow = False

    def listen(self, callback: Callable[[], None]) -> Callable[[], None]:
        """Call `callback` (from the program's thread) whenever something new is shown; returns the
        function that stops it."""
        with self._lock:
            self._listeners.append(callback)

        def remove() -> None:
            with self._lock:
                if callback in self._listeners:
                    self._listeners.remove(callback)

        return remove

    def _notify(self) -> None:
        with self._lock:
            listeners = list(self._listeners)
        for callback in listeners:
            callback()
