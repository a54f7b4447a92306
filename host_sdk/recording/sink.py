"""Where recorded messages go: an MCAP file and/or a live Foxglove WebSocket server, in one process.

`FoxgloveSink` is built on `foxglove-sdk` (the `foxglove` extra, imported when a sink is opened):
one `foxglove.Context` per sink, so two recorders in one program never share channels; the MCAP
writer and the server are both sinks of that context, so a message is encoded once and goes to
both. Well-known Foxglove messages are protobuf; RoverLink's own are JSON with a JSON schema.

Sources publish through the `Publisher` methods below with times on the robot's clock (seconds,
`robot.now()`); `TimeBase` maps them to wall-clock nanoseconds, which is what Foxglove shows.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from host_sdk.extras import require

LOG_LEVELS = ("DEBUG", "INFO", "WARN", "ERROR")


class Publisher(Protocol):
    """What a source publishes into (a `FoxgloveSink`, or a test's fake)."""

    def json(self, topic: str, schema: dict[str, Any], message: dict[str, Any], time_s: float) -> None: ...

    def pose(self, topic: str, time_s: float, *, frame_id: str, x: float, y: float, theta: float) -> None: ...

    def poses(
        self, topic: str, time_s: float, *, frame_id: str, poses: Sequence[tuple[float, float, float]]
    ) -> None: ...

    def transform(
        self, topic: str, time_s: float, *, parent: str, child: str, x: float, y: float, theta: float, z: float = 0.0
    ) -> None: ...

    def log(self, topic: str, time_s: float, *, level: str, text: str, name: str) -> None: ...

    def laser_scan(
        self,
        topic: str,
        time_s: float,
        *,
        frame_id: str,
        start_angle: float,
        end_angle: float,
        ranges: Sequence[float],
        intensities: Sequence[float],
    ) -> None: ...

    def compressed_image(self, topic: str, time_s: float, *, frame_id: str, fmt: str, data: bytes) -> None: ...


@dataclass(frozen=True, slots=True)
class TimeBase:
    """Maps the robot's clock (seconds: monotonic, or an emulator's virtual time) to Unix nanoseconds."""

    clock_s: float
    epoch_ns: int

    @classmethod
    def now(cls, clock_s: float) -> TimeBase:
        return cls(clock_s, time.time_ns())

    def ns(self, time_s: float) -> int:
        return self.epoch_ns + round((time_s - self.clock_s) * 1e9)


def _yaw_quaternion(theta: float) -> tuple[float, float, float, float]:
    return 0.0, 0.0, math.sin(theta / 2), math.cos(theta / 2)


class FoxgloveSink:
    """An MCAP file (`mcap_path`) and/or a live server (`serve=True`) on `host:port` (0: any free port)."""

    def __init__(
        self,
        time_base: TimeBase,
        *,
        mcap_path: str | Path | None = None,
        overwrite: bool = False,
        serve: bool = False,
        host: str = "127.0.0.1",
        port: int = 8765,
        name: str = "RoverLink",
    ) -> None:
        fg = _import_foxglove()
        self._fg = fg
        self.time_base = time_base
        self.context = fg.Context()
        self.mcap_path = Path(mcap_path) if mcap_path is not None else None
        self.host = host
        self._writer: Any = None
        self._server: Any = None
        self._lock = threading.Lock()
        self._channels: dict[str, Any] = {}
        self.counts: dict[str, int] = {}
        """Messages published per topic."""
        self.closed = False
        if self.mcap_path is not None:
            if self.mcap_path.exists() and not overwrite:
                raise FileExistsError(f"{self.mcap_path} exists: choose another name or allow overwriting")
            self._writer = fg.open_mcap(str(self.mcap_path), allow_overwrite=overwrite, context=self.context)
        if serve:
            try:
                self._server = fg.start_server(name=name, host=host, port=port, context=self.context)
            except Exception:
                if self._writer is not None:
                    self._writer.close()
                raise

    @property
    def port(self) -> int | None:
        """The live server's port (None without a server)."""
        return int(self._server.port) if self._server is not None else None

    @property
    def url(self) -> str | None:
        """ws:// address to open in Foxglove (None without a server); on a wildcard address
        (0.0.0.0), this machine's loopback one."""
        if self._server is None:
            return None
        host = {"0.0.0.0": "127.0.0.1", "::": "[::1]"}.get(self.host, self.host)
        return f"ws://{host}:{self.port}"

    # -- Publisher ------------------------------------------------------------------------------
    def json(self, topic: str, schema: dict[str, Any], message: dict[str, Any], time_s: float) -> None:
        channel = self._channel(topic, lambda: self._fg.Channel(topic, schema=schema, context=self.context))
        self._log(topic, channel, message, time_s)

    def pose(self, topic: str, time_s: float, *, frame_id: str, x: float, y: float, theta: float) -> None:
        m = self._fg.messages
        msg = m.PoseInFrame(timestamp=self._stamp(time_s), frame_id=frame_id, pose=self._pose(x, y, theta))
        self._typed(topic, "PoseInFrameChannel", msg, time_s)

    def poses(self, topic: str, time_s: float, *, frame_id: str, poses: Sequence[tuple[float, float, float]]) -> None:
        m = self._fg.messages
        msg = m.PosesInFrame(timestamp=self._stamp(time_s), frame_id=frame_id, poses=[self._pose(*p) for p in poses])
        self._typed(topic, "PosesInFrameChannel", msg, time_s)

    def transform(
        self, topic: str, time_s: float, *, parent: str, child: str, x: float, y: float, theta: float, z: float = 0.0
    ) -> None:
        m = self._fg.messages
        qx, qy, qz, qw = _yaw_quaternion(theta)
        tf = m.FrameTransform(
            timestamp=self._stamp(time_s),
            parent_frame_id=parent,
            child_frame_id=child,
            translation=m.Vector3(x=x, y=y, z=z),
            rotation=m.Quaternion(x=qx, y=qy, z=qz, w=qw),
        )
        self._typed(topic, "FrameTransformsChannel", m.FrameTransforms(transforms=[tf]), time_s)

    def log(self, topic: str, time_s: float, *, level: str, text: str, name: str) -> None:
        m = self._fg.messages
        levels = {
            "DEBUG": m.LogLevel.Debug,
            "INFO": m.LogLevel.Info,
            "WARN": m.LogLevel.Warning,
            "ERROR": m.LogLevel.Error,
        }
        msg = m.Log(timestamp=self._stamp(time_s), level=levels.get(level, m.LogLevel.Info), message=text, name=name)
        self._typed(topic, "LogChannel", msg, time_s)

    def laser_scan(
        self,
        topic: str,
        time_s: float,
        *,
        frame_id: str,
        start_angle: float,
        end_angle: float,
        ranges: Sequence[float],
        intensities: Sequence[float],
    ) -> None:
        m = self._fg.messages
        msg = m.LaserScan(
            timestamp=self._stamp(time_s),
            frame_id=frame_id,
            pose=self._pose(0.0, 0.0, 0.0),
            start_angle=start_angle,
            end_angle=end_angle,
            ranges=list(ranges),
            intensities=list(intensities),
        )
        self._typed(topic, "LaserScanChannel", msg, time_s)

    def compressed_image(self, topic: str, time_s: float, *, frame_id: str, fmt: str, data: bytes) -> None:
        m = self._fg.messages
        msg = m.CompressedImage(timestamp=self._stamp(time_s), frame_id=frame_id, data=data, format=fmt)
        self._typed(topic, "CompressedImageChannel", msg, time_s)

    # -- internals ------------------------------------------------------------------------------
    def _stamp(self, time_s: float) -> Any:
        ns = self.time_base.ns(time_s)
        return self._fg.messages.Timestamp(sec=ns // 1_000_000_000, nsec=ns % 1_000_000_000)

    def _pose(self, x: float, y: float, theta: float) -> Any:
        m = self._fg.messages
        qx, qy, qz, qw = _yaw_quaternion(theta)
        return m.Pose(position=m.Vector3(x=x, y=y, z=0.0), orientation=m.Quaternion(x=qx, y=qy, z=qz, w=qw))

    def _typed(self, topic: str, channel_class: str, message: Any, time_s: float) -> None:
        cls = getattr(self._fg.channels, channel_class)
        channel = self._channel(topic, lambda: cls(topic, context=self.context))
        self._log(topic, channel, message, time_s)

    def _channel(self, topic: str, make: Any) -> Any:
        with self._lock:
            channel = self._channels.get(topic)
            if channel is None:
                channel = self._channels[topic] = make()
            return channel

    def _log(self, topic: str, channel: Any, message: Any, time_s: float) -> None:
        with self._lock:
            if self.closed:
                return
            self.counts[topic] = self.counts.get(topic, 0) + 1
        channel.log(message, log_time=self.time_base.ns(time_s))

    def close(self) -> None:
        """Finish the MCAP file (its summary and index) and stop the server. Idempotent."""
        with self._lock:
            if self.closed:
                return
            self.closed = True
        if self._writer is not None:
            self._writer.close()
        if self._server is not None:
            self._server.stop()
        for channel in self._channels.values():
            channel.close()


def _import_foxglove() -> Any:
    fg = require("foxglove", "foxglove", "recording (MCAP files and the live Foxglove view)")
    require("foxglove.channels", "foxglove", "recording")
    require("foxglove.messages", "foxglove", "recording")
    return fg
