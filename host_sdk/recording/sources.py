"""What gets recorded: sources that publish into a sink, and the `Recorder` that owns them.

A source is anything with `start(publisher)`, `poll(now_s)` and `stop()`. It publishes from its
own callbacks (the robot's FEEDBACK and LOG callbacks run on the SDK's I/O thread) and does
periodic work, such as asking the board for its link counters, in `poll`, which the program that
owns the recorder calls from its loop. The sensors plug in the same way (`SensorSource`, or
`Recorder.attach(robot, sensors=...)`): a scan becomes `publisher.laser_scan(TOPIC_SCAN, ...)`, an
image `compressed_image(TOPIC_IMAGE, ...)`, an IMU sample `json(TOPIC_IMU, IMU_SCHEMA, ...)`.

    with Recorder.attach(robot, mcap_path="run.mcap", serve=True) as recorder:
        while driving:
            robot.drive(...)
            recorder.poll()                 # link statistics, the path
    print(recorder.summary)
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

from host_sdk import FeedbackSample, LinkStatistics, Robot, RoverLinkError
from host_sdk.enums import LogLevel
from host_sdk.geometry import sensor_mounts
from host_sdk.recording.schemas import (
    FEEDBACK_SCHEMA,
    FRAME_BASE,
    FRAME_ODOM,
    LINK_SCHEMA,
    SETPOINT_SCHEMA,
    TOPIC_FEEDBACK,
    TOPIC_LINK,
    TOPIC_LOG,
    TOPIC_ODOMETRY,
    TOPIC_PATH,
    TOPIC_SETPOINT,
    TOPIC_TF,
    TOPIC_WHEELS,
    WHEELS_SCHEMA,
    feedback_message,
    link_message,
    wheels_message,
)
from host_sdk.recording.sensors import SensorSource
from host_sdk.recording.sink import FoxgloveSink, Publisher, TimeBase
from host_sdk.sensors.hub import Sensors


class Source(Protocol):
    name: str

    def start(self, out: Publisher) -> None: ...

    def poll(self, now_s: float) -> None: ...

    def stop(self) -> None: ...


_RATE_FIELDS = ("frames_sent", "bytes_sent", "frames_received", "bytes_received", "feedback_received", "crc_errors")


def link_rates(before: LinkStatistics | None, after: LinkStatistics, dt_s: float) -> dict[str, float]:
    """Per-second rates of the host's counters between two snapshots (empty for the first)."""
    if before is None or dt_s <= 0:
        return {}
    return {f"{name}_per_s": (getattr(after, name) - getattr(before, name)) / dt_s for name in _RATE_FIELDS}


def board_counters(robot: Robot) -> dict[str, int] | None:
    """The board's LINK_STATS counters (None when the board does not answer)."""
    try:
        reply = robot.board_link_stats()
    except RoverLinkError:
        return None
    return {k: int(v) for k, v in reply.fields().items() if k != "req_seq"}


class RobotSource:
    """Feedback, wheels, odometry pose and path, the odom -> base_link transform, LOG lines and
    both sides' link statistics of one robot. Read-only: it never arms or commands."""

    name = "robot"

    def __init__(
        self,
        robot: Robot,
        *,
        link_period_s: float = 1.0,
        board_stats: bool = True,
        path_spacing_m: float = 0.02,
        path_max_poses: int = 5000,
        path_period_s: float = 1.0,
    ) -> None:
        self.robot = robot
        self.link_period_s = link_period_s
        self.path_period_s = path_period_s
        self.board_stats = board_stats
        self.path_spacing_m = path_spacing_m
        self.path_max_poses = path_max_poses
        self.feedback_seen = 0
        self.logs_seen = 0
        self._out: Publisher | None = None
        self._unsubscribe: list[Callable[[], None]] = []
        self._path: list[tuple[float, float, float]] = []
        self._path_dirty = False
        self._last_path_s: float | None = None
        self._last_link: tuple[float, LinkStatistics] | None = None

    def start(self, out: Publisher) -> None:
        self._out = out
        self._unsubscribe = [self.robot.on_feedback(self._on_feedback), self.robot.on_log(self._on_log)]

    def stop(self) -> None:
        for unsubscribe in self._unsubscribe:
            unsubscribe()
        self._unsubscribe = []
        self._publish_path(self.robot.now())  # the whole path, to where the recording ends

    def _publish_path(self, now_s: float) -> None:
        if self._out is not None and self._path_dirty:
            self._path_dirty = False
            self._last_path_s = now_s
            self._out.poses(TOPIC_PATH, now_s, frame_id=FRAME_ODOM, poses=list(self._path))

    def _on_feedback(self, sample: FeedbackSample) -> None:
        out = self._out
        if out is None:
            return
        self.feedback_seen += 1
        t = sample.host_time_s
        out.json(TOPIC_FEEDBACK, FEEDBACK_SCHEMA, feedback_message(sample), t)
        out.json(TOPIC_WHEELS, WHEELS_SCHEMA, wheels_message(sample), t)
        pose = sample.pose
        if pose is None:
            return
        out.pose(TOPIC_ODOMETRY, t, frame_id=FRAME_ODOM, x=pose.x_m, y=pose.y_m, theta=pose.theta_rad)
        out.transform(TOPIC_TF, t, parent=FRAME_ODOM, child=FRAME_BASE, x=pose.x_m, y=pose.y_m, theta=pose.theta_rad)
        last = self._path[-1] if self._path else None
        if last is None or math.hypot(pose.x_m - last[0], pose.y_m - last[1]) >= self.path_spacing_m:
            self._path.append((pose.x_m, pose.y_m, pose.theta_rad))
            if len(self._path) > self.path_max_poses:
                del self._path[::2]  # keep the whole path, at half the resolution
            self._path_dirty = True

    def _on_log(self, level: LogLevel, text: str) -> None:
        if self._out is not None:
            self.logs_seen += 1
            self._out.log(TOPIC_LOG, self.robot.now(), level=level.name, text=text, name="firmware")

    def setpoint(self, speeds_m_s: Sequence[float], steering_rad: float = 0.0) -> None:
        """Record what the owning program commanded (wheel rim speeds, or speed and steering)."""
        if self._out is not None:
            message = {"speed_m_s": list(speeds_m_s), "steering_rad": steering_rad}
            self._out.json(TOPIC_SETPOINT, SETPOINT_SCHEMA, message, self.robot.now())

    def poll(self, now_s: float) -> None:
        out = self._out
        if out is None:
            return
        if self._last_path_s is None or now_s - self._last_path_s >= self.path_period_s:
            self._publish_path(now_s)
        if self._last_link is not None and now_s - self._last_link[0] < self.link_period_s:
            return
        stats = self.robot.stats
        board = board_counters(self.robot) if self.board_stats else None
        before = self._last_link
        rates = link_rates(before[1] if before else None, stats, now_s - before[0] if before else 0.0)
        self._last_link = (now_s, stats)
        out.json(TOPIC_LINK, LINK_SCHEMA, link_message(stats, board, rates), now_s)


@dataclass
class RecordingSummary:
    path: Path | None
    bytes: int
    duration_s: float
    counts: dict[str, int] = field(default_factory=dict)
    url: str | None = None

    def lines(self) -> list[str]:
        where = str(self.path) if self.path is not None else "(no file)"
        total = sum(self.counts.values())
        head = f"recorded {total} messages in {self.duration_s:.1f} s to {where}"
        if self.path is not None:
            head += f" ({self.bytes / 1024:.1f} KiB)"
        return [head] + [f"  {topic:<28} {n:>7}" for topic, n in sorted(self.counts.items())]


class Recorder:
    """A sink and the sources publishing into it; `attach(robot, ...)` builds the usual one."""

    def __init__(self, sink: FoxgloveSink, sources: Sequence[Source], clock: Callable[[], float]) -> None:
        self.sink = sink
        self.sources = list(sources)
        self._clock = clock
        self._start_s = clock()
        self.summary: RecordingSummary | None = None
        for source in self.sources:
            source.start(sink)

    @classmethod
    def attach(
        cls,
        robot: Robot,
        *,
        mcap_path: str | Path | None = None,
        overwrite: bool = False,
        serve: bool = False,
        host: str = "127.0.0.1",
        port: int = 8765,
        sources: Sequence[Source] = (),
        board_stats: bool = True,
        sensors: Sensors | None = None,
    ) -> Recorder:
        """Record `robot` (and any further `sources`) to `mcap_path` and/or a live server; with
        `sensors` (roverlink.sensors), their scans, images and IMU samples too."""
        sink = FoxgloveSink(
            TimeBase.now(robot.now()), mcap_path=mcap_path, overwrite=overwrite, serve=serve, host=host, port=port
        )
        extra = list(sources)
        if sensors is not None and not sensors.empty:
            extra.append(SensorSource(sensors, sensor_mounts(robot, sensors.kinds())))
        return cls(sink, [RobotSource(robot, board_stats=board_stats), *extra], robot.now)

    @property
    def robot_source(self) -> RobotSource | None:
        return next((s for s in self.sources if isinstance(s, RobotSource)), None)

    def poll(self) -> None:
        now = self._clock()
        for source in self.sources:
            source.poll(now)

    def close(self) -> RecordingSummary:
        """Stop the sources, finish the file, stop the server; returns (and keeps) the summary."""
        if self.summary is not None:
            return self.summary
        for source in self.sources:
            source.stop()
        url = self.sink.url
        self.sink.close()
        path = self.sink.mcap_path
        size = os.path.getsize(path) if path is not None and path.exists() else 0
        self.summary = RecordingSummary(path, size, self._clock() - self._start_s, dict(self.sink.counts), url)
        return self.summary

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
