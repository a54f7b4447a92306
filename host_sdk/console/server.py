"""The console's web server (aiohttp, in a thread of its own with its own event loop).

Routes: `/` the page and `/static/...` its scripts (shipped in the package: the robot has no
internet); `/ws` the WebSocket (state and camera frames out, requests in); `POST /api/stop` the stop
button's own path, which disarms at once and never waits behind video; `/stream.mjpg` the camera as
MJPEG (for players such as VLC, and to compare costs); `/api/frame.jpg` one frame.

Every request passes `Access` (host, token) first; a WebSocket's Origin must be the page's own.
One browser drives at a time (the first to send a command), the others watch; anyone may stop, and
a watcher may take the wheel (`take`: the driver is told, and the robot stops for the new driver to
decide). A driver not heard for DRIVER_GONE_S (hidden, frozen, cut off, or reconnected over a
new socket) holds the wheel no more: the next browser to send a command drives. The driving
page's keep-alive (`alive`, every third of the command lifetime; watchers' are ignored) is what
following lasts on (Hub).
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import math
import struct
import threading
from collections.abc import Awaitable, Callable
from importlib import resources
from typing import Any

from host_sdk.console.access import COOKIE, Access
from host_sdk.console.hub import Drive, Hub, Select
from host_sdk.errors import CommandRangeError, TransportError
from host_sdk.extras import require

Handler = Callable[[Any], Awaitable[Any]]
STATIC = ("index.html", "console.js", "console.css")
MIME = {".html": "text/html", ".js": "text/javascript", ".css": "text/css"}
FRAME_HEADER = struct.Struct("<I")
"""A binary WebSocket message: the frame's id (uint32, little-endian), then its JPEG."""


def _web() -> Any:
    return require("aiohttp.web", "console", "the web console")


DRIVER_GONE_S = 2.0
"""A driving page sends its keep-alive every third of the command lifetime: one not heard for this
long is gone (hidden, frozen, cut off), and the next browser to send a command drives."""


class ConsoleServer:
    """Serves `hub` on `access.host`:`port` (0: any free port; `port` says which after `start`)."""

    def __init__(
        self,
        hub: Hub,
        access: Access,
        port: int = 8080,
        *,
        on_stop: Callable[[], None],
        jpeg_quality: int = 70,
        max_speed: tuple[float, float] = (0.5, 2.0),
        on_dismiss: Callable[[int], None] = lambda refusal_id: None,
    ) -> None:
        if not 0 <= port <= 65535:
            raise CommandRangeError("port", port, "0 to 65535")
        if not 10 <= jpeg_quality <= 100:
            raise CommandRangeError("jpeg_quality", jpeg_quality, "10 to 100")
        self.web = _web()
        self.cv2 = require("cv2", "vision", "the web console's camera view")
        self.hub = hub
        self.access = access
        self.port = port
        self.on_stop = on_stop
        self.on_dismiss = on_dismiss
        """A refusal the page shows was dismissed (by its id): gone for every page."""
        self.jpeg_quality = jpeg_quality
        self.max_speed = max_speed
        """Largest linear (m/s) and angular (rad/s) speed a browser may ask for."""
        self.driver: Any = None
        self.clients = 0
        self._jpeg: tuple[int, bytes] = (0, b"")
        self._loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._runner: Any = None
        self._changed: asyncio.Event | None = None
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self._unlisten: Callable[[], None] | None = None
        self._closing = False

    # -- lifecycle ----------------------------------------------------------------------------------
    def start(self) -> None:
        """Listen (raises if the address cannot be bound); returns once it does."""
        self._thread = threading.Thread(target=self._run, name="roverlink-console", daemon=True)
        self._thread.start()
        self._ready.wait()
        error = self._error
        if isinstance(error, OSError):  # a name that does not resolve, an address not ours, a port in use
            where = f"{self.access.host}:{self.port}"
            reason = (error.strerror or str(error)).rsplit(": ", 1)[-1]  # asyncio repeats the address first
            raise TransportError(f"the console cannot listen on {where}: {reason}", where, error) from error
        if error is not None:
            raise error

    @property
    def thread_id(self) -> int | None:
        """The server thread's native id (for per-thread CPU accounting), once started."""
        return None if self._thread is None else self._thread.native_id

    def close(self) -> None:
        if self._unlisten is not None:
            self._unlisten()
        loop, thread = self._loop, self._thread
        if loop is not None and thread is not None and thread.is_alive():
            asyncio.run_coroutine_threadsafe(self._shutdown(), loop).result(timeout=5.0)
            loop.call_soon_threadsafe(loop.stop)
            thread.join(timeout=5.0)

    def _run(self) -> None:
        loop = asyncio.new_event_loop()
        self._loop = loop
        asyncio.set_event_loop(loop)
        try:
            loop.run_until_complete(self._serve())
        except BaseException as exc:  # reported to start()
            self._error = exc
            self._ready.set()
            return
        self._ready.set()
        loop.run_forever()
        loop.close()

    async def _serve(self) -> None:
        web = self.web
        self._changed = asyncio.Event()

        @web.middleware  # type: ignore[untyped-decorator]
        async def guard(request: Any, handler: Handler) -> Any:
            return await self._guard(request, handler)

        app = web.Application(middlewares=[guard])
        app.router.add_get("/", self._page)
        app.router.add_get("/static/{name}", self._static)
        app.router.add_get("/ws", self._socket)
        app.router.add_post("/api/stop", self._stop)
        app.router.add_get("/api/frame.jpg", self._snapshot)
        app.router.add_get("/stream.mjpg", self._mjpeg)
        self._runner = web.AppRunner(app, access_log=None, shutdown_timeout=1.0)
        await self._runner.setup()
        site = web.TCPSite(self._runner, self.access.host, self.port)
        await site.start()
        if self.port == 0:
            self.port = site._server.sockets[0].getsockname()[1]
        loop = asyncio.get_running_loop()

        def changed() -> None:
            loop.call_soon_threadsafe(self._wake)

        self._unlisten = self.hub.listen(changed)

    async def _shutdown(self) -> None:
        self._closing = True
        self._wake()  # the streams waiting for a frame end now
        if self._runner is not None:
            await self._runner.cleanup()

    def _wake(self) -> None:
        """Something new was shown (on the server's loop): wake whoever waits for it."""
        assert self._changed is not None
        self._changed.set()
        self._changed = asyncio.Event()

    async def _changes(self, seen: int, what: Callable[[], int]) -> None:
        """Until `what()` differs from `seen` (a version or a frame id)."""
        while what() == seen and not self._closing:
            assert self._changed is not None
            await self._changed.wait()

    # -- access -------------------------------------------------------------------------------------
    def _presented(self, request: Any) -> str | None:
        auth = request.headers.get("Authorization", "")
        if auth.startswith("Bearer "):
            return str(auth[7:])
        token = request.query.get("token") or request.cookies.get(COOKIE)
        return None if token is None else str(token)

    async def _guard(self, request: Any, handler: Handler) -> Any:
        web, access = self.web, self.access
        if not access.host_ok(request.headers.get("Host")):
            return web.Response(status=403, text="forbidden: this console answers to its loopback address only\n")
        if not access.allows(self._presented(request)):
            return web.Response(status=401, text="unauthorized: open the URL with ?token=... the console printed\n")
        response = await handler(request)
        token = request.query.get("token")
        if token is not None and isinstance(response, web.Response):
            response.set_cookie(COOKIE, token, httponly=True, samesite="Strict")
        return response

    # -- pages --------------------------------------------------------------------------------------
    async def _page(self, request: Any) -> Any:
        return self._file("index.html")

    async def _static(self, request: Any) -> Any:
        name = request.match_info["name"]
        if name not in STATIC:
            raise self.web.HTTPNotFound()
        return self._file(name)

    def _file(self, name: str) -> Any:
        body = resources.files("host_sdk.console").joinpath("static").joinpath(name).read_bytes()
        kind = MIME[name[name.rindex(".") :]]
        return self.web.Response(body=body, content_type=kind, headers={"Cache-Control": "no-store"})

    async def _stop(self, request: Any) -> Any:
        self.hub.stop()
        self.on_stop()
        return self.web.json_response({"stopped": True})

    def _jpeg_of_latest(self) -> tuple[int, bytes] | None:
        _, frame, _, _ = self.hub.latest()
        if frame is None:
            return None
        if self._jpeg[0] != frame.id and frame.jpeg is not None:  # the camera's own: no encoding here
            self._jpeg = (frame.id, frame.jpeg)
        elif self._jpeg[0] != frame.id:  # encoded once per frame, whoever asks
            ok, buf = self.cv2.imencode(".jpg", frame.image, [self.cv2.IMWRITE_JPEG_QUALITY, self.jpeg_quality])
            if ok:
                self._jpeg = (frame.id, buf.tobytes())
        return self._jpeg

    async def _snapshot(self, request: Any) -> Any:
        latest = self._jpeg_of_latest()
        if latest is None:
            raise self.web.HTTPServiceUnavailable(text="no camera frame yet\n")
        return self.web.Response(body=latest[1], content_type="image/jpeg")

    async def _mjpeg(self, request: Any) -> Any:
        web = self.web
        response = web.StreamResponse(headers={"Content-Type": "multipart/x-mixed-replace; boundary=frame"})
        await response.prepare(request)
        sent = 0
        while not self._closing:
            latest = await self._next_frame(sent)
            if latest is None:
                continue
            sent, jpeg = latest
            head = f"--frame\r\nContent-Type: image/jpeg\r\nContent-Length: {len(jpeg)}\r\n\r\n".encode()
            try:
                await response.write(head + jpeg + b"\r\n")
            except (ConnectionError, RuntimeError):
                break
        return response

    async def _next_frame(self, after: int) -> tuple[int, bytes] | None:
        await self._changes(after, lambda: self.hub.frame_id)
        return self._jpeg_of_latest()

    # -- the WebSocket --------------------------------------------------------------------------------
    async def _socket(self, request: Any) -> Any:
        web = self.web
        if not self.access.origin_ok(request.headers.get("Origin"), request.headers.get("Host")):
            return web.Response(status=403, text="forbidden: the WebSocket's Origin is not this console's page\n")
        ws = web.WebSocketResponse(heartbeat=5.0)
        await ws.prepare(request)
        self.clients += 1
        sender = asyncio.ensure_future(self._send_loop(ws))
        try:
            lifetime = self.hub.command_lifetime_s
            await ws.send_json(
                {
                    "type": "hello",
                    "driving": False,
                    "max_speed": list(self.max_speed),
                    "command_lifetime_s": lifetime,
                    "keepalive_s": lifetime / 3,
                    "autonomous": self.hub.autonomous,
                }
            )
            async for msg in ws:
                if msg.type == web.WSMsgType.TEXT:
                    await self._on_message(ws, msg.data)
        finally:
            sender.cancel()
            self.clients -= 1
            if self.driver is ws:
                self.driver = None
                self.hub.stop_driving()  # a closed tab stops the robot now, not after the lifetime
        return ws

    async def _send_loop(self, ws: Any) -> None:
        version, frame_id = -1, 0
        mine: dict[str, Any] = {}
        while not ws.closed and not self._closing:
            await self._changes(version, lambda: self.hub.version)
            version, frame, overlay, state = self.hub.latest(since=version)  # only what changed (a scan is large)
            now = {"driving": self.driver is ws, "clients": self.clients}
            state |= {k: v for k, v in now.items() if mine.get(k) != v}
            mine = now
            if state:
                await ws.send_json({"type": "state", **state})
            if frame is not None and frame.id != frame_id:
                latest = self._jpeg_of_latest()
                if latest is not None:
                    frame_id = latest[0]
                    await ws.send_json({"type": "overlay", "frame": frame_id, "time_s": frame.time_s, **overlay})
                    await ws.send_bytes(FRAME_HEADER.pack(frame_id) + latest[1])

    async def _on_message(self, ws: Any, text: str) -> None:
        try:
            msg = json.loads(text)
            kind = msg["type"]
        except (ValueError, KeyError, TypeError):
            await ws.send_json({"type": "error", "error": "a message must be JSON with a 'type'"})
            return
        if kind == "stop":  # anyone may stop
            self.hub.stop()
            self.on_stop()
            return
        if kind == "dismiss":  # anyone may: it is only what the pages show
            try:
                self.on_dismiss(int(msg["id"]))
            except (CommandRangeError, KeyError, TypeError, ValueError) as exc:
                await ws.send_json({"type": "error", "error": f"dismiss: {exc}"})
            return
        if kind == "alive":  # the driver's counts; a watcher's keeps nothing alive
            if self.driver is ws:
                self.hub.alive()
            return
        if kind == "take":
            await self._take_wheel(ws)
            return
        if kind not in ("drive", "select", "follow", "arm", "target"):
            await ws.send_json({"type": "error", "error": f"unknown message type {kind!r}"})
            return
        if self.driver is None or self.driver.closed:
            self.driver = ws
        elif self.driver is not ws and self._driver_lapsed():
            await self._hand_over(ws, "another browser drives now: yours had gone quiet (hidden, frozen or cut off)")
        if self.driver is not ws:
            await ws.send_json(
                {"type": "error", "error": "another browser is driving: you can watch, stop, or take the wheel"}
            )
            return
        self.hub.alive()
        try:
            self._apply(kind, msg)
        except (CommandRangeError, KeyError, TypeError, ValueError) as exc:
            await ws.send_json({"type": "error", "error": str(exc)})

    def _driver_lapsed(self) -> bool:
        """The driving browser has not been heard for DRIVER_GONE_S (a hidden or frozen tab, a
        laptop whose Wi-Fi went, or the same page reconnected over a new socket while the old one
        is not closed yet): following ended for it long since, and it no longer holds the wheel."""
        return self.hub.clock() - self.hub.alive_s > max(DRIVER_GONE_S, 4 * self.hub.command_lifetime_s)

    async def _take_wheel(self, ws: Any) -> None:
        """A watcher drives from now on; the robot stops (drive and following end) until it decides."""
        if self.driver is not ws:
            await self._hand_over(
                ws, "another browser took the wheel: you are watching now (Take the wheel to drive again)"
            )

    async def _hand_over(self, ws: Any, told: str) -> None:
        """`ws` drives from now on; the robot stops until it decides; the previous driver is told."""
        before = self.driver
        self.driver = ws
        self.hub.stop()
        self.hub.alive()
        if before is not None and not before.closed:
            with contextlib.suppress(ConnectionError, RuntimeError):
                await before.send_json({"type": "notice", "text": told})

    def _apply(self, kind: str, msg: dict[str, Any]) -> None:
        hub = self.hub
        if kind == "drive":
            linear = _number(msg, "linear", self.max_speed[0])
            angular = _number(msg, "angular", self.max_speed[1])
            hub.post(drive=Drive(linear, angular, hub.clock(), override=msg.get("override") is True))
        elif kind == "select":
            frame = hub.frame(int(msg["frame"]))
            if frame is None:
                raise CommandRangeError(
                    "frame",
                    msg["frame"],
                    f"one of the last {self.hub.keep_frames} frames shown "
                    "(the picture the box was drawn on is gone: draw it again)",
                )
            box = tuple(float(v) for v in msg["box"])
            h, w = frame.image.shape[:2]
            if len(box) != 4 or not (
                box[0] >= 0
                and box[1] >= 0
                and box[2] >= 6
                and box[3] >= 6
                and box[0] + box[2] <= w
                and box[1] + box[3] <= h
            ):
                raise CommandRangeError("box", list(box), f"x, y, w, h inside the {w}x{h} frame, at least 6 px a side")
            hub.post(select=Select(frame, (box[0], box[1], box[2], box[3])))
        elif kind == "follow":
            hub.post(follow=bool(msg["on"]))
        elif kind == "arm":
            if not msg["on"]:
                hub.stop()
                self.on_stop()  # disarming is stopping: at once, from here
            hub.post(arm=bool(msg["on"]))
        elif kind == "target":
            hub.post(target_kind=str(msg["kind"]))


def _number(msg: dict[str, Any], name: str, limit: float) -> float:
    value = float(msg[name])
    if not math.isfinite(value) or abs(value) > limit:
        raise CommandRangeError(name, value, f"-{limit:g} to {limit:g}")
    return value
