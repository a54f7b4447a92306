"""MJPEG over HTTP with the SDK's own parser (no FFmpeg needed): a multipart stream with and without
X-Frame/X-Timestamp, a URL that answers one JPEG per request, a server that closes, wrong answers."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import cv2
import numpy as np
import pytest

from host_sdk.sensors import CameraSource, SensorClosedError, SensorOpenError

Handler = Callable[[BaseHTTPRequestHandler], None]


def jpeg(shade: int, size: tuple[int, int] = (64, 48)) -> bytes:
    image = np.full((size[1], size[0], 3), shade, np.uint8)
    ok, data = cv2.imencode(".jpg", image)
    assert ok
    return bytes(data)


def part(data: bytes, headers: dict[str, str]) -> bytes:
    lines = [
        f"{k}: {v}" for k, v in {"Content-Type": "image/jpeg", "Content-Length": str(len(data)), **headers}.items()
    ]
    return ("--frame\r\n" + "\r\n".join(lines) + "\r\n\r\n").encode() + data + b"\r\n"


@pytest.fixture
def serve() -> Iterator[Callable[[Handler], str]]:
    servers: list[ThreadingHTTPServer] = []

    def start(respond: Handler) -> str:
        class H(BaseHTTPRequestHandler):
            def do_GET(self) -> None:
                respond(self)

            def log_message(self, format: str, *args: object) -> None:
                return

        httpd = ThreadingHTTPServer(("127.0.0.1", 0), H)
        httpd.daemon_threads = True
        threading.Thread(target=httpd.serve_forever, daemon=True).start()
        servers.append(httpd)
        return f"http://127.0.0.1:{httpd.server_address[1]}/stream"

    yield start
    for httpd in servers:
        httpd.shutdown()
        httpd.server_close()


def multipart(parts: list[bytes], hold: threading.Event | None = None) -> Handler:
    def respond(h: BaseHTTPRequestHandler) -> None:
        h.send_response(200)
        h.send_header("Content-Type", "multipart/x-mixed-replace; boundary=frame")
        h.end_headers()
        for p in parts:
            h.wfile.write(p)
            h.wfile.flush()
        if hold is not None:
            hold.wait(10)  # the stream stays open until the test is done

    return respond


def test_stream_keeps_the_parts_timestamps_counters_and_bytes(serve: Callable[[Handler], str]) -> None:
    done = threading.Event()
    frames = [
        part(jpeg(40 * i), {"X-Timestamp": f"{10 + i / 30:.6f}", "X-Frame": str(n)}) for i, n in enumerate((1, 2, 5))
    ]
    url = serve(multipart(frames, done))
    try:
        with CameraSource(url) as cam:
            got = [cam.read(5.0) for _ in range(3)]
            assert cam.queued and cam.detail == "HTTP MJPEG stream"
            assert [f.seq for f in got] == [1, 2, 3]
            assert [f.device_time_s for f in got] == pytest.approx([10.0, 10 + 1 / 30, 10 + 2 / 30])
            assert cam.dropped == 2  # X-Frame 2 -> 5
            assert got[2].jpeg == jpeg(80) and got[2].image.shape == (48, 64, 3)
            assert abs(int(got[1].image.mean()) - 40) <= 2
            assert cam.latest() is None  # nothing new, and no wait
    finally:
        done.set()


def test_a_stream_the_server_closes_ends_with_closed_not_a_hang(serve: Callable[[Handler], str]) -> None:
    url = serve(multipart([part(jpeg(10), {}), part(jpeg(20), {})]))  # no X-Frame or X-Timestamp
    with CameraSource(url) as cam:
        first, second = cam.read(5.0), cam.read(5.0)
        assert first.device_time_s is None and second.seq == 2
        with pytest.raises(SensorClosedError, match="the server closed the stream after 2 frames"):
            cam.read(5.0)


def test_a_url_answering_one_jpeg_is_fetched_again_for_each_frame(serve: Callable[[Handler], str]) -> None:
    count = [0]

    def snapshot(h: BaseHTTPRequestHandler) -> None:
        count[0] += 1
        data = jpeg(min(250, count[0] * 30))
        h.send_response(200)
        h.send_header("Content-Type", "image/jpeg")
        h.send_header("Content-Length", str(len(data)))
        h.end_headers()
        h.wfile.write(data)

    with CameraSource(serve(snapshot)) as cam:
        frames = [cam.read(5.0) for _ in range(3)]
        assert cam.detail == "HTTP JPEG snapshots"
    assert [f.seq for f in frames] == [1, 2, 3] and all(f.image.shape == (48, 64, 3) for f in frames)
    assert count[0] >= 3 and frames[0].jpeg is not None and frames[0].jpeg[:2] == b"\xff\xd8"


def test_wrong_answers_name_what_came(serve: Callable[[Handler], str]) -> None:
    def html(h: BaseHTTPRequestHandler) -> None:
        h.send_response(200)
        h.send_header("Content-Type", "text/html")
        h.end_headers()
        h.wfile.write(b"<html>camera settings</html>")

    def missing(h: BaseHTTPRequestHandler) -> None:
        h.send_error(404)

    with pytest.raises(SensorOpenError, match=r"the server sent text/html, not an MJPEG stream"):
        CameraSource(serve(html))
    with pytest.raises(SensorOpenError, match="the server answered 404"):
        CameraSource(serve(missing))
    with pytest.raises(SensorOpenError, match=r"http://127.0.0.1:1/stream: could not connect"):
        CameraSource("http://127.0.0.1:1/stream", timeout_s=2.0)  # nothing listens on port 1


def test_a_slow_camera_keeps_streaming_and_close_does_not_wait_for_it(serve: Callable[[Handler], str]) -> None:
    done = threading.Event()

    def two_fps(h: BaseHTTPRequestHandler) -> None:
        h.send_response(200)
        h.send_header("Content-Type", "multipart/x-mixed-replace; boundary=frame")
        h.end_headers()
        for n in range(1, 4):
            h.wfile.write(part(jpeg(30 * n), {"X-Frame": str(n)}))
            h.wfile.flush()
            if done.wait(0.5):  # a camera at 2 frames per second
                return
        done.wait(10)

    with CameraSource(serve(two_fps), timeout_s=3.0) as cam:
        frames = [cam.read(3.0) for _ in range(3)]  # half a second apart: no read gives up between
        assert [f.seq for f in frames] == [1, 2, 3] and cam.dropped == 0
        started = time.monotonic()
    assert time.monotonic() - started < 1.0  # close woke the reader, which was waiting for bytes
    done.set()


def test_a_stream_that_stalls_is_asked_for_again(serve: Callable[[Handler], str]) -> None:
    requests = [0]
    done = threading.Event()

    def stalls_once(h: BaseHTTPRequestHandler) -> None:
        requests[0] += 1
        first = requests[0] == 1
        multipart([part(jpeg(60 if first else 120), {"X-Frame": "1" if first else "7"})])(h)
        if first:
            done.wait(10)  # then nothing: the client gives up on this connection

    try:
        with CameraSource(serve(stalls_once), timeout_s=0.5) as cam:
            first, second = cam.read(3.0), cam.read(3.0)
        assert requests[0] == 2 and abs(int(second.image.mean()) - 120) <= 2
        assert first.seq == 1 and second.seq == 2
    finally:
        done.set()
