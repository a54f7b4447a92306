"""MJPEG streams read with the SDK's own parser: an emulator's byte stream (`emudev://`), and
HTTP (ESP32-CAM, IP cameras, `roverlink emulate --camera`) over http.client, so neither needs
OpenCV's FFmpeg. The parts' `X-Timestamp` and `X-Frame` headers are kept when a server sends them.
"""

from __future__ import annotations

import contextlib
import http.client
import socket
import threading
import time
import urllib.parse
from collections import deque

from host_sdk.sensors.camera.frame import Capture
from host_sdk.sensors.errors import SensorClosedError, SensorOpenError
from host_sdk.sensors.mjpeg import MjpegParser
from host_sdk.transport import Transport

QUEUED_FRAMES = 8
"""Frames an HTTP stream keeps for a reader that falls behind (older ones are dropped, as a V4L2
queue drops them); the emulator's byte stream keeps its own."""
STALLS = 3
"""Times in a row an HTTP stream may send nothing for `timeout_s` (each time it is requested again)
before it counts as ended."""


class ByteStreamBackend:
    """Multipart JPEG parts over a Transport (a plugin's `emudev://` endpoint)."""

    queued = True
    fps: float | None = None
    skipped = 0

    def __init__(self, port: Transport) -> None:
        self._port = port
        self._parser = MjpegParser()
        self.virtual = port.virtual
        self.detail = "MJPEG byte stream"

    def clock(self) -> float:
        return self._port.clock()

    def fetch(self, timeout_s: float) -> list[Capture]:
        data = self._port.read(timeout_s)
        if data:
            self._parser.receive_data(data, self._port.clock())
        return [Capture(p.t, jpeg=p.jpeg, counter=p.frame, device_t=p.timestamp) for p in self._parser.parts()]

    def heard(self) -> str:
        counters = self._parser.counters
        return f"{counters.bytes_received} bytes, {counters.parts} frames"

    def close(self) -> None:
        self._port.close()


class HttpMjpegBackend:
    """A `multipart/x-mixed-replace` stream (or a URL that answers one JPEG, fetched again for each
    frame), read by a thread of its own into a short queue."""

    queued = True
    virtual = False

    def __init__(self, url: str, *, fps: float | None, timeout_s: float) -> None:
        self.url = url
        self.fps = fps
        self._timeout_s = timeout_s
        self._parser = MjpegParser()
        self._cond = threading.Condition()
        self._queue: deque[Capture] = deque()
        self._stop = threading.Event()
        self._ended: str | None = None
        self._frames = 0
        self.skipped = 0
        self._sock: socket.socket | None = None
        self._conn, response = self._request()
        kind = response.headers.get_content_type()
        self._snapshot = kind == "image/jpeg"
        if not self._snapshot and not kind.startswith("multipart/"):
            self._conn.close()
            raise SensorOpenError(
                f"camera {url}: the server sent {kind}, not an MJPEG stream (multipart/x-mixed-replace) or a JPEG"
            )
        self.detail = "HTTP JPEG snapshots" if self._snapshot else "HTTP MJPEG stream"
        self._thread = threading.Thread(target=self._run, args=(response,), name="roverlink-camera-http", daemon=True)
        self._thread.start()

    def _request(self) -> tuple[http.client.HTTPConnection, http.client.HTTPResponse]:
        parts = urllib.parse.urlsplit(self.url)
        factory = http.client.HTTPSConnection if parts.scheme == "https" else http.client.HTTPConnection
        path = (parts.path or "/") + (f"?{parts.query}" if parts.query else "")
        conn = factory(parts.hostname or "", parts.port, timeout=self._timeout_s)
        try:
            conn.request("GET", path, headers={"Accept": "multipart/x-mixed-replace, image/jpeg"})
            self._sock = conn.sock  # (the connection lets go of it when the response reads to the close)
            response = conn.getresponse()
        except OSError as exc:
            conn.close()
            raise SensorOpenError(f"camera {self.url}: could not connect ({exc})") from exc
        if response.status != 200:
            conn.close()
            raise SensorOpenError(f"camera {self.url}: the server answered {response.status} {response.reason}")
        return conn, response

    def _run(self, response: http.client.HTTPResponse) -> None:
        stalls = 0
        try:
            while not self._stop.is_set():
                if self._snapshot:
                    self._snapshot_once(response)
                    response = self._again()
                    continue
                try:
                    data = response.read1(65536)
                except TimeoutError:
                    # A socket file that timed out cannot be read again: ask for the stream anew.
                    stalls += 1
                    if stalls >= STALLS:
                        raise SensorClosedError(f"nothing came for {STALLS} x {self._timeout_s:g} s") from None
                    response = self._again()
                    continue
                if not data:
                    if self._stop.is_set():
                        return
                    raise SensorClosedError(f"the server closed the stream after {self._frames} frames")
                stalls = 0
                self._parser.receive_data(data, time.monotonic())
                self._keep(
                    [Capture(p.t, jpeg=p.jpeg, counter=p.frame, device_t=p.timestamp) for p in self._parser.parts()]
                )
        except (OSError, http.client.HTTPException) as exc:  # SensorClosedError and SensorOpenError too
            if not self._stop.is_set():
                self._end(str(exc) or type(exc).__name__)
        finally:
            self._conn.close()

    def _snapshot_once(self, response: http.client.HTTPResponse) -> None:
        body = response.read()
        self._parser.counters.bytes_received += len(body)
        if body[:2] == b"\xff\xd8":
            self._keep([Capture(time.monotonic(), jpeg=body)])

    def _again(self) -> http.client.HTTPResponse:
        """The next snapshot, or the stream asked for again after a stall."""
        if self._snapshot and self.fps:  # pace the requests at the asked rate; else as fast as answered
            self._stop.wait(1.0 / self.fps)
        self._conn.close()
        self._conn, response = self._request()
        return response

    def _keep(self, captures: list[Capture]) -> None:
        if not captures:
            return
        with self._cond:
            self._queue.extend(captures)
            self._frames += len(captures)
            while len(self._queue) > QUEUED_FRAMES:
                if self._queue.popleft().counter is None:  # (a counter shows the gap by itself)
                    self.skipped += 1
            self._cond.notify_all()

    def _end(self, why: str) -> None:
        with self._cond:
            self._ended = why
            self._cond.notify_all()

    def clock(self) -> float:
        return time.monotonic()

    def fetch(self, timeout_s: float) -> list[Capture]:
        with self._cond:
            self._cond.wait_for(lambda: self._queue or self._ended is not None, timeout=max(timeout_s, 0.0))
            if not self._queue and self._ended is not None:
                raise SensorClosedError(f"camera {self.url}: {self._ended}")
            out = list(self._queue)
            self._queue.clear()
            return out

    def heard(self) -> str:
        return f"{self._parser.counters.bytes_received} bytes, {self._frames} frames"

    def close(self) -> None:
        self._stop.set()
        sock = self._sock
        if sock is not None:  # wakes the reading thread from its wait for bytes
            with contextlib.suppress(OSError):
                sock.shutdown(socket.SHUT_RDWR)
        self._thread.join(timeout=2.0)
        with contextlib.suppress(OSError):
            self._conn.close()
