"""The emulated camera as a network camera shows it: JPEG frames in a multipart (MJPEG) stream.

Each frame is one part:

    --roverlinkframe\\r\\n
    Content-Type: image/jpeg\\r\\n
    Content-Length: N\\r\\n
    X-Timestamp: 12.345678\\r\\n        virtual time of the exposure's middle, seconds
    X-Frame: 42\\r\\n                   frame counter (gaps: frames the reader missed)
    \\r\\n
    <N bytes of JPEG>\\r\\n

Over HTTP (`roverlink emulate --camera`) the parts follow a `multipart/x-mixed-replace` response,
which `cv2.VideoCapture("http://127.0.0.1:PORT/stream.mjpg")` opens like any IP camera; in-process
the same parts go through a byte pipe (`emudev://`), and the SDK's camera source reads them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from emulator.rng import Streams
from emulator.sensors.camera import CameraOptions
from emulator.sensors.lidar import PoseAt
from emulator.sensors.photo import renderer_for
from emulator.world.scene import Scene
from protocol.errors import import_optional
from protocol.sensors import CameraSpec, Mount

BOUNDARY = "roverlinkframe"
CONTENT_TYPE = f"multipart/x-mixed-replace; boundary={BOUNDARY}"
JPEG_QUALITY = 85


@dataclass(frozen=True, slots=True)
class FrameTruth:
    """What one rendered frame showed, for scoring a tracker."""

    seq: int
    time_us: int
    pose: tuple[float, float, float]
    """The robot's world pose at the exposure."""
    target_bbox: tuple[int, int, int, int] | None
    """The target's visible pixels (x0, y0, x1, y1; x1, y1 exclusive), or None if not seen."""
    target_distance_m: float | None
    """From the camera to the target's centre."""


TRUTH_FRAMES = 256
"""Frames whose FrameTruth a CameraDevice keeps."""


@dataclass(frozen=True, slots=True)
class Frame:
    seq: int
    time_us: int
    jpeg: bytes

    def part(self) -> bytes:
        head = (
            f"--{BOUNDARY}\r\nContent-Type: image/jpeg\r\nContent-Length: {len(self.jpeg)}\r\n"
            f"X-Timestamp: {self.time_us / 1e6:.6f}\r\nX-Frame: {self.seq}\r\n\r\n"
        )
        return head.encode("ascii") + self.jpeg + b"\r\n"


STALE_FRAMES = 2
"""On the real clock, a frame more than this many periods behind the wall clock is skipped."""


class CameraDevice:
    """Renders at `fps` on the virtual clock while anyone listens, and hands each JPEG to them."""

    kind = "camera"
    name = "camera"

    def __init__(
        self,
        spec: CameraSpec,
        mount: Mount,
        options: CameraOptions,
        streams: Streams,
        yaw_rate: Callable[[], float],
        *,
        realtime_us: Callable[[], Callable[[], int] | None] = lambda: None,
    ) -> None:
        # OpenCV encodes every frame: without it, fail when the camera is attached, not at its first frame.
        import_optional("cv2", "vision", "the emulated camera")
        self.spec = spec
        self.options = options
        self.renderer = renderer_for(spec, mount, options)
        self.rng = np.random.Generator(np.random.PCG64(streams.get("sensor:camera").getrandbits(64)))
        self.yaw_rate = yaw_rate
        self.listeners: list[Callable[[Frame], None]] = []
        self.always = False
        """Render even with nobody listening (a served camera: a client may connect any time)."""
        self.seq = 0
        self.frames_rendered = 0
        self.frames_skipped = 0
        """Frames not rendered on the real clock because the emulator was behind the wall clock by
        more than STALE_FRAMES periods (numbered all the same: a reader sees them as dropped)."""
        self._realtime_us = realtime_us
        self._index = 0
        self.last_image: np.ndarray | None = None
        self.truth: dict[int, FrameTruth] = {}
        """Ground truth of the last TRUTH_FRAMES frames, by frame number (X-Frame)."""

    def _record_truth(self, scene: Scene, t: int, pose: tuple[float, float, float]) -> None:
        target = scene.target_pose()
        distance = None
        if target is not None:
            m = self.renderer.mount
            cx = pose[0] + math.cos(pose[2]) * m.x_m - math.sin(pose[2]) * m.y_m
            cy = pose[1] + math.sin(pose[2]) * m.x_m + math.cos(pose[2]) * m.y_m
            distance = math.hypot(target[0] - cx, target[1] - cy)
        self.truth[self.seq] = FrameTruth(self.seq, t, pose, self.renderer.target_bbox, distance)
        while len(self.truth) > TRUTH_FRAMES:  # the oldest first (frames skipped have none)
            del self.truth[next(iter(self.truth))]

    def frame_time_us(self, index: int) -> int:
        return round(index * 1e6 / self.options.fps)

    def update(self, scene: Scene, until_us: int, pose_at: PoseAt) -> None:
        cv2 = import_optional("cv2", "vision", "the emulated camera")
        wall = self._realtime_us()
        stale_us = STALE_FRAMES * 1e6 / self.options.fps
        while self.frame_time_us(self._index) < until_us:
            t = self.frame_time_us(self._index)
            self._index += 1
            if not (self.listeners or self.always):
                continue
            # Behind the wall clock (a busy machine, a stall at start): rendering frames that are
            # already stale would only fall further behind, as a real camera drops them instead.
            if wall is not None and wall() - t > stale_us:
                self.seq += 1
                self.frames_skipped += 1
                continue
            x, y, th = pose_at(np.array([t], dtype=np.int64))
            pose = (float(x[0]), float(y[0]), float(th[0]))
            image = self.renderer.render(scene, pose, self.yaw_rate(), self.rng, time_s=t / 1e6)
            self.last_image = image
            ok, jpeg = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
            if not ok:  # pragma: no cover - OpenCV encodes any uint8 BGR image
                continue
            self.seq += 1
            self.frames_rendered += 1
            self._record_truth(scene, t, pose)
            frame = Frame(self.seq, t, jpeg.tobytes())
            for listener in list(self.listeners):
                listener(frame)
