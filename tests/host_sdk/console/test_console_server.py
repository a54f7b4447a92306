"""The console's server over real sockets: who gets in, who drives, what the page receives."""

from __future__ import annotations

import json
import threading
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator

import numpy as np
import pytest
from websockets.exceptions import InvalidStatus
from websockets.sync.client import ClientConnection, connect

from host_sdk.console.access import COOKIE, Access
from host_sdk.console.hub import Hub
from host_sdk.console.server import FRAME_HEADER, ConsoleServer
from tests.support.wait import Deadline, wait_until

cv2 = pytest.importorskip("cv2")


class Served:
    def __init__(self, host: str = "127.0.0.1", token: str | None = None) -> None:
        self.hub = Hub(command_lifetime_s=0.25)
        self.stops = threading.Event()
        self.server = ConsoleServer(self.hub, Access.for_host(host, token), 0, on_stop=self.stops.set)
        self.server.start()
        self.base = f"http://127.0.0.1:{self.server.port}"
        self.token = self.server.access.token

    def get(
        self, path: str, headers: dict[str, str] | None = None, method: str = "GET"
    ) -> tuple[int, bytes, dict[str, str]]:
        req = urllib.request.Request(self.base + path, headers=headers or {}, method=method)
        try:
            with urllib.request.urlopen(req, timeout=5) as r:
                return r.status, r.read(), dict(r.headers)
        except urllib.error.HTTPError as e:
            return e.code, e.read(), dict(e.headers)

    def socket(self, *, token: str | None = None, origin: str | None = "own") -> ClientConnection:
        headers = {}
        if token is not None:
            headers["Cookie"] = f"{COOKIE}={token}"
        if origin == "own":
            origin = self.base
        kwargs = {"origin": origin} if origin else {}
        return connect(f"ws://127.0.0.1:{self.server.port}/ws", additional_headers=headers, open_timeout=5, **kwargs)


@pytest.fixture
def served() -> Iterator[Served]:
    s = Served()
    yield s
    s.server.close()


@pytest.fixture
def exposed() -> Iterator[Served]:
    s = Served("0.0.0.0")
    yield s
    s.server.close()


def until(check: Callable[[], object], timeout_s: float = 5.0) -> None:
    wait_until(check, timeout_s)


def receive(ws: ClientConnection, kind: str, timeout_s: float = 5.0) -> dict:  # type: ignore[type-arg]
    deadline = Deadline(timeout_s)
    while True:
        msg = ws.recv(timeout=deadline.remaining(floor=0.01))
        if isinstance(msg, str) and json.loads(msg)["type"] == kind:
            return json.loads(msg)  # type: ignore[no-any-return]


def test_the_page_and_its_scripts_are_served_from_the_package(served: Served) -> None:
    status, body, headers = served.get("/")
    assert status == 200 and b"RoverLink console" in body and headers["Content-Type"].startswith("text/html")
    for name in ("console.js", "console.css"):
        assert served.get(f"/static/{name}")[0] == 200
    assert served.get("/static/../../etc/passwd")[0] == 404
    assert served.get("/static/secret.py")[0] == 404
    assert b"http://" not in body and b"https://" not in body  # nothing fetched from elsewhere


def test_on_loopback_a_foreign_host_name_is_refused(served: Served) -> None:
    assert served.get("/", {"Host": "evil.example"})[0] == 403


def test_off_loopback_every_route_wants_the_token(exposed: Served) -> None:
    token = exposed.token
    assert token
    for path in ("/", "/static/console.js", "/api/frame.jpg", "/stream.mjpg", "/ws"):
        assert exposed.get(path)[0] == 401, path
        assert exposed.get(path + "?token=wrong-token-value")[0] == 401, path
    assert exposed.get("/api/stop", method="POST")[0] == 401
    assert not exposed.stops.is_set()
    with pytest.raises(InvalidStatus), exposed.socket():
        pass
    with pytest.raises(InvalidStatus), exposed.socket(token="wrong-token-value"):
        pass
    # With it: in the URL (which sets the cookie the page's own requests carry), as a cookie, as a header.
    status, _, headers = exposed.get(f"/?token={token}")
    assert status == 200 and f"{COOKIE}={token}" in headers["Set-Cookie"] and "HttpOnly" in headers["Set-Cookie"]
    assert exposed.get("/static/console.js", {"Cookie": f"{COOKIE}={token}"})[0] == 200
    assert exposed.get("/static/console.js", {"Authorization": f"Bearer {token}"})[0] == 200
    with exposed.socket(token=token):
        pass
    assert exposed.get("/api/stop", {"Cookie": f"{COOKIE}={token}"}, method="POST")[0] == 200
    assert exposed.stops.is_set()


def test_a_websocket_from_another_origin_is_refused(served: Served) -> None:
    with pytest.raises(InvalidStatus) as refused, served.socket(origin="http://evil.example"):
        pass
    assert refused.value.response.status_code == 403
    with served.socket(origin=None):  # a program, not a browser
        pass


def test_one_browser_drives_the_others_watch_and_anyone_stops(served: Served) -> None:
    with served.socket() as first, served.socket() as second:
        drive_in_turn(served, first, second)


def drive_in_turn(served: Served, first: ClientConnection, second: ClientConnection) -> None:
    hub = served.hub
    first.send(json.dumps({"type": "drive", "linear": 0.2, "angular": 0.5}))
    until(lambda: hub.take().drive is not None)
    second.send(json.dumps({"type": "drive", "linear": -0.2, "angular": 0.0}))
    assert "another browser is driving" in receive(second, "error")["error"]
    assert hub.take().drive.linear_m_s == 0.2  # type: ignore[union-attr]
    second.send(json.dumps({"type": "stop"}))
    until(served.stops.is_set)
    # The driver leaves: its command is forgotten at once and the next browser may drive.
    first.send(json.dumps({"type": "drive", "linear": 0.2, "angular": 0.0}))
    first.close()
    until(lambda: hub.take().drive is None)
    second.send(json.dumps({"type": "drive", "linear": -0.1, "angular": 0.0}))
    until(lambda: (d := hub.take().drive) is not None and d.linear_m_s == -0.1)


def test_requests_out_of_range_are_refused_naming_the_field(served: Served) -> None:
    with served.socket() as ws:
        refused(served, ws)


def refused(served: Served, ws: ClientConnection) -> None:
    ws.send(json.dumps({"type": "drive", "linear": 9.0, "angular": 0.0}))
    error = receive(ws, "error")["error"]
    assert "linear" in error and "9" in error and "0.5" in error
    ws.send(json.dumps({"type": "drive", "linear": "nan", "angular": 0.0}))
    assert "linear" in receive(ws, "error")["error"]
    ws.send("not json")
    assert "JSON" in receive(ws, "error")["error"]
    ws.send(json.dumps({"type": "fly"}))
    assert "fly" in receive(ws, "error")["error"]
    frame = served.hub.show_frame(np.zeros((240, 320, 3), np.uint8), 0.0)
    ws.send(json.dumps({"type": "select", "frame": frame.id, "box": [300, 200, 50, 60]}))
    error = receive(ws, "error")["error"]
    assert "box" in error and "320x240" in error
    ws.send(json.dumps({"type": "select", "frame": 12345, "box": [10, 10, 50, 60]}))
    assert "frame" in receive(ws, "error")["error"]
    assert served.hub.take().select is None


def test_frames_arrive_with_their_overlay_and_a_box_names_its_frame(served: Served) -> None:
    with served.socket() as ws:
        frames_and_boxes(served.hub, ws)


def frames_and_boxes(hub: Hub, ws: ClientConnection) -> None:
    image = np.zeros((240, 320, 3), np.uint8)
    image[100:140, 150:190] = (0, 0, 255)
    frame = hub.show_frame(image, 1.5, {"box": [150, 100, 40, 40], "state": "tracking", "confidence": 0.9})
    overlay = receive(ws, "overlay")
    assert overlay["frame"] == frame.id and overlay["box"] == [150, 100, 40, 40] and overlay["time_s"] == 1.5
    data = ws.recv(timeout=5)
    assert isinstance(data, bytes)
    (frame_id,) = FRAME_HEADER.unpack_from(data)
    decoded = cv2.imdecode(np.frombuffer(data[FRAME_HEADER.size :], np.uint8), cv2.IMREAD_COLOR)
    assert frame_id == frame.id and decoded.shape == image.shape
    assert decoded[120, 170, 2] > 200 and decoded[10, 10].max() < 30
    # Newer frames come; a box drawn on the first still names the first.
    for t in range(5):
        hub.show_frame(np.zeros((240, 320, 3), np.uint8), 2.0 + t)
    ws.send(json.dumps({"type": "select", "frame": frame.id, "box": [148, 98, 44, 44]}))
    until(lambda: (s := hub.take().select) is not None and s.frame is frame and s.box == (148, 98, 44, 44))


def test_the_mjpeg_stream_and_a_snapshot(served: Served) -> None:
    assert served.get("/api/frame.jpg")[0] == 503
    served.hub.show_frame(np.full((240, 320, 3), 128, np.uint8), 0.0)
    status, body, headers = served.get("/api/frame.jpg")
    assert status == 200 and headers["Content-Type"] == "image/jpeg" and body[:2] == b"\xff\xd8"
    with urllib.request.urlopen(served.base + "/stream.mjpg", timeout=5) as stream:
        assert stream.headers["Content-Type"].startswith("multipart/x-mixed-replace")
        head = stream.read(60)
        assert head.startswith(b"--frame\r\nContent-Type: image/jpeg")


def test_a_drive_command_lapses_after_its_lifetime() -> None:
    now = [0.0]
    hub = Hub(command_lifetime_s=0.25, clock=lambda: now[0])
    from host_sdk.console.hub import Drive

    hub.post(drive=Drive(0.3, 0.0, 0.0))
    now[0] = 0.2
    assert hub.take().drive is not None
    assert hub.take().drive is not None  # kept until it lapses
    now[0] = 0.26
    assert hub.take().drive is None


def test_a_page_is_sent_only_the_state_that_changed_and_a_new_one_all_of_it(served: Served) -> None:
    """A scan is 360 points: resending it with every 50 Hz pose would be most of the server's work."""
    scan = {"points": [[1.0, 0.0]] * 360, "range_m": 4.0}
    served.hub.show_state(scan=scan, pose={"x": 0.0, "y": 0.0, "theta": 0.0})
    with served.socket() as ws:
        first = receive(ws, "state")
        assert first["scan"] == scan and first["pose"]["x"] == 0.0 and first["driving"] is False
        served.hub.show_state(pose={"x": 0.5, "y": 0.0, "theta": 0.0})
        update = receive(ws, "state")
        assert update == {"type": "state", "pose": {"x": 0.5, "y": 0.0, "theta": 0.0}}
        with served.socket() as late:  # a page opened later gets the whole state
            state = receive(late, "state")
            assert state["scan"] == scan and state["pose"]["x"] == 0.5 and state["clients"] == 2
        served.hub.show_state(mode="idle")
        assert {k for k in receive(ws, "state") if k != "clients"} == {"type", "mode"}
