"""The emulated camera as a network camera: an MJPEG stream over HTTP on 127.0.0.1.

`cv2.VideoCapture("http://127.0.0.1:PORT/stream.mjpg")` opens it as it opens an IP camera. Each
client gets every frame rendered after it connected (a slow client skips to the newest, as a
network camera's server does); any path serves the stream. Frames are rendered only while a client
is connected, so a served camera costs nothing until someone watches.
"""

from __future__ import annotations

import contextlib
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

from emulator.sensors.mjpeg import CONTENT_TYPE, CameraDevice, Frame


class MjpegServer:
    def __init__(self, camera: CameraDevice, port: int = 0) -> None:
        self._cond = threading.Condition()
        self._frame: Frame | None = None
        self._stopping = False
        self._clients = 0
        self.camera = camera
        server = self

        class Handler(BaseHTTPRequestHandler):
            def do_GET(self) -> None:
                self.send_response(200)
                self.send_header("Content-Type", CONTENT_TYPE)
                self.send_header("Cache-Control", "no-cache")
                self.end_headers()
                seen = -1
                server.client(+1)
                try:
                    with contextlib.suppress(OSError):
                        while True:
                            frame = server.wait_frame(seen)
                            if frame is None:
                                return
                            seen = frame.seq
                            self.wfile.write(frame.part())
                            self.wfile.flush()
                finally:
                    server.client(-1)

            def log_message(self, format: str, *args: object) -> None:
                return

        self.httpd = ThreadingHTTPServer(("127.0.0.1", port), Handler)
        self.httpd.daemon_threads = True
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}/stream.mjpg"
        self._thread = threading.Thread(target=self.httpd.serve_forever, name="mjpeg-http", daemon=True)
        self._thread.start()

    def client(self, change: int) -> None:
        with self._cond:
            self._clients += change
            listening = self.publish in self.camera.listeners
            if self._clients > 0 and not listening:
                self.camera.listeners.append(self.publish)
            elif self._clients == 0 and listening:
                self.camera.listeners.remove(self.publish)

    def publish(self, frame: Frame) -> None:
        with self._cond:
            self._frame = frame
            self._cond.notify_all()

    def wait_frame(self, seen: int) -> Frame | None:
        """The newest frame after `seen` (None: the server is stopping)."""
        with self._cond:
            while not self._stopping and (self._frame is None or self._frame.seq <= seen):
                self._cond.wait(0.5)
            return None if self._stopping else self._frame

    def close(self) -> None:
        with self._cond:
            self._stopping = True
            self._cond.notify_all()
        self.httpd.shutdown()
        self.httpd.server_close()
