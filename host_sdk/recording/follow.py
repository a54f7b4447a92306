"""What a follow run records besides the robot (`roverlink follow --foxglove`, or a robot program
with a `FollowPilot`): the filtered scan, the camera with the tracked box, and the behaviour's state
(with the manoeuvre it plans), as a source for the recorder (MCAP files and the live Foxglove view,
shared with `roverlink record` and `monitor`).

A source has `start(publisher)`, `poll(now_s)` and `stop()`; this one reads the pilot's latest
picture when polled (the follow loop polls the recorder once per control period) and publishes at
most `image_hz` camera frames a second (JPEG-encoding every frame would cost more than tracking it).
"""

from __future__ import annotations

import math
from typing import Any, Protocol

import numpy as np

from host_sdk.autonomy import FollowPilot
from host_sdk.extras import require

TOPIC_SCAN = "/scan"
TOPIC_IMAGE = "/camera/image/compressed"
TOPIC_FOLLOW = "/roverlink/follow"
FOLLOW_SCHEMA: dict[str, Any] = {
    "type": "object",
    "properties": {
        "mode": {"type": "string"},
        "linear_m_s": {"type": "number"},
        "angular_rad_s": {"type": "number"},
        "gap_m": {"type": ["number", "null"]},
        "target_x_m": {"type": ["number", "null"]},
        "target_y_m": {"type": ["number", "null"]},
        "tracked": {"type": "boolean"},
        "confidence": {"type": "number"},
        "plan_x_m": {"type": "array", "items": {"type": "number"}},
        "plan_y_m": {"type": "array", "items": {"type": "number"}},
    },
}


class Publisher(Protocol):
    def json(self, topic: str, schema: dict[str, Any], message: dict[str, Any], time_s: float) -> None: ...

    def laser_scan(
        self,
        topic: str,
        time_s: float,
        *,
        frame_id: str,
        start_angle: float,
        end_angle: float,
        ranges: list[float],
        intensities: list[float],
    ) -> None: ...

    def compressed_image(self, topic: str, time_s: float, *, frame_id: str, fmt: str, data: bytes) -> None: ...


class FollowSource:
    name = "follow"

    def __init__(self, pilot: FollowPilot, image_hz: float = 5.0) -> None:
        self.pilot = pilot
        self.image_period_s = 1.0 / image_hz
        self._out: Publisher | None = None
        self._next_image = -math.inf
        self._scan_time: float | None = None

    def start(self, out: Publisher) -> None:
        self._out = out

    def poll(self, now_s: float) -> None:
        out, pilot = self._out, self.pilot
        if out is None:
            return
        scan = pilot.last_scan
        if scan is not None and scan.time_s != self._scan_time:
            self._scan_time = scan.time_s
            ranges = np.nan_to_num(scan.ranges_m, nan=math.inf).tolist()
            out.laser_scan(
                TOPIC_SCAN,
                scan.time_s,
                frame_id="base_link",
                start_angle=float(scan.angles_rad[0]),
                end_angle=float(scan.angles_rad[-1]),
                ranges=ranges,
                intensities=[],
            )
        d = pilot.decision
        track = pilot.last_track
        if d is not None:
            message = {
                "mode": d.mode.value,
                "linear_m_s": d.linear_m_s,
                "angular_rad_s": d.angular_rad_s,
                "gap_m": d.gap_m,
                "target_x_m": d.target.x_m if d.target is not None else None,
                "target_y_m": d.target.y_m if d.target is not None else None,
                "tracked": bool(track is not None and track.found),
                "confidence": track.confidence if track is not None else 0.0,
                # The planned manoeuvre (base frame): where the robot means to be over the next seconds.
                "plan_x_m": [x for x, _ in d.manoeuvre.path_xy] if d.manoeuvre is not None else [],
                "plan_y_m": [y for _, y in d.manoeuvre.path_xy] if d.manoeuvre is not None else [],
            }
            out.json(TOPIC_FOLLOW, FOLLOW_SCHEMA, message, now_s)
        frame = pilot.last_frame
        if frame is not None and now_s >= self._next_image:
            self._next_image = now_s + self.image_period_s
            out.compressed_image(TOPIC_IMAGE, frame.time_s, frame_id="camera", fmt="jpeg", data=self._jpeg(frame.image))

    def _jpeg(self, image: np.ndarray) -> bytes:
        cv2 = require("cv2", "vision", "recording the camera")
        picture = image.copy()
        track = self.pilot.last_track
        if track is not None and track.box is not None:
            x, y, w, h = (round(v) for v in track.box)
            cv2.rectangle(picture, (x, y), (x + w, y + h), (0, 255, 0), 2)
        ok, data = cv2.imencode(".jpg", picture, [cv2.IMWRITE_JPEG_QUALITY, 80])
        return bytes(data) if ok else b""

    def stop(self) -> None:
        self._out = None
