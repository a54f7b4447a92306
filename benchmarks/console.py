"""The web console's cost on the robot and its camera-to-browser latency, with a real browser.

    python benchmarks/console.py                  # 20 s per transport
    python benchmarks/console.py --seconds 60

A feeder thread plays the robot program: a 320x240 camera frame (a photo with a box moving across
it) at 30 fps, a 360-point scan at 10 Hz and the pose at 50 Hz, shown through the console's `Hub`
as raw images (as picamera2 and V4L2 give them: the server encodes each JPEG once). Headless
Chromium (Debian's) shows it in three runs:

- `websocket`: the console's page, frames and state over its WebSocket;
- `frames`: the same page with no scan or pose (the frames' own cost);
- `mjpeg`: the `/stream.mjpg` URL in an <img> (frames only, as MJPEG).

Measured:

- the console server thread's CPU time (from /proc: user + system) per second of wall time, as a
  share of one core, JPEG encoding included;
- on the page, camera-to-browser latency: from the frame being shown to the hub to its being drawn
  on the page's canvas (both clocks are this machine's wall clock), median and 95th percentile;
  frames drawn per second.

The feeder's own cost (making frames and scans) is the robot program's and not counted.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import statistics
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from selenium import webdriver
from selenium.webdriver.chrome.service import Service

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the checkout: its packages and test photos

from host_sdk.console.access import Access
from host_sdk.console.hub import Hub
from host_sdk.console.server import ConsoleServer
from tests.support.photo_sequences import photo

WIDTH, HEIGHT = 320, 240


def thread_cpu_s(native_id: int) -> float:
    """User + system CPU seconds of one of this process's threads."""
    with open(f"/proc/self/task/{native_id}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def backdrop() -> np.ndarray:
    """A real photograph (the project's test photos: tests/data/photos) as the scene."""
    image = photo("rocket_launch.jpg")
    return np.ascontiguousarray(cv2.resize(image, (WIDTH, HEIGHT), interpolation=cv2.INTER_AREA))


class Feeder:
    """The robot program's side: frames at `fps`, scans at 10 Hz, poses at 50 Hz."""

    def __init__(self, hub: Hub, fps: float, state: bool = True) -> None:
        self.hub, self.fps, self.state = hub, fps, state
        self.scene = backdrop()
        self.shown: dict[int, float] = {}
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self.run, daemon=True)

    def run(self) -> None:
        start = time.monotonic()
        tick = 0
        angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
        while not self.stop.is_set():
            t = tick / 150.0  # a 150 Hz clock: frames every 150/fps ticks, scans every 15, poses every 3
            if tick % round(150 / self.fps) == 0:
                image = self.scene.copy()
                x = int((WIDTH - 40) * (0.5 + 0.5 * math.sin(t)))
                image[100:160, x : x + 40] = (200, 40, 200)
                frame = self.hub.show_frame(image, t, {"box": [x, 100, 40, 60], "state": "tracking", "confidence": 0.9})
                self.shown[frame.id] = time.time()
            if self.state and tick % 15 == 0:
                ranges = 2.0 + 0.5 * np.sin(angles * 3 + t)
                points = [
                    [round(float(r * math.cos(a)), 3), round(float(r * math.sin(a)), 3)]
                    for a, r in zip(angles, ranges, strict=True)
                ]
                self.hub.show_state(scan={"points": points, "range_m": 4.0})
            if self.state and tick % 3 == 0:
                self.hub.show_state(pose={"x": round(0.1 * t, 3), "y": 0.0, "theta": 0.0})
            tick += 1
            time.sleep(max(0.0, start + tick / 150.0 - time.monotonic()))


def browser() -> Any:
    chromium, driver = shutil.which("chromium"), shutil.which("chromedriver")
    if not (chromium and driver):
        raise SystemExit("needs Debian's chromium and chromium-driver (apt install chromium chromium-driver)")
    options = webdriver.ChromeOptions()
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"):
        options.add_argument(arg)
    options.binary_location = chromium
    return webdriver.Chrome(service=Service(driver), options=options)


# Wraps the page's drawCamera to note when each frame was drawn (wall clock, ms).
RECORD_DRAWS = """
window.drawn = [];
const draw = window.drawCamera;
window.drawCamera = function () { draw(); window.drawn.push([view.frameId, Date.now()]); };
"""


def measure(transport: str, seconds: float, fps: float) -> dict[str, float]:
    hub = Hub()
    server = ConsoleServer(hub, Access.for_host("127.0.0.1"), 0, on_stop=lambda: None)
    server.start()
    tid = server.thread_id
    assert tid is not None
    feeder = Feeder(hub, fps, state=transport != "frames")
    feeder.thread.start()
    page = browser()
    try:
        url = f"http://127.0.0.1:{server.port}/"
        if transport == "mjpeg":  # an <img> on the stream, as a page would show it (its load never ends)
            page.get(url + "api/frame.jpg")
            page.execute_script("document.body.innerHTML = `<img src='${arguments[0]}'>`", url + "stream.mjpg")
        else:  # the console's page
            page.get(url)
            deadline = time.monotonic() + 10
            while not page.execute_script("return Number(document.body.dataset.frame || 0)"):
                assert time.monotonic() < deadline, "no frame on the page"
                time.sleep(0.05)
            page.execute_script(RECORD_DRAWS)
        time.sleep(2.0)  # settle
        cpu0, t0 = thread_cpu_s(tid), time.monotonic()
        time.sleep(seconds)
        cpu1, t1 = thread_cpu_s(tid), time.monotonic()
        result = {"cpu_share": (cpu1 - cpu0) / (t1 - t0)}
        if transport != "mjpeg":
            drawn = page.execute_script("return window.drawn")
            latencies = [at - feeder.shown[fid] * 1000 for fid, at in drawn if fid in feeder.shown]
            window = [d for d in drawn if d[1] >= drawn[-1][1] - seconds * 1000]
            result |= {
                "latency_median_ms": statistics.median(latencies),
                "latency_p95_ms": float(np.percentile(latencies, 95)),
                "drawn_fps": len(window) / seconds,
            }
        return result
    finally:
        page.quit()
        feeder.stop.set()
        server.close()


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--seconds", type=float, default=20.0, help="measured seconds per transport (default 20)")
    p.add_argument("--fps", type=float, default=30.0, help="camera frames per second (default 30)")
    args = p.parse_args(argv)
    print(f"console server, {WIDTH}x{HEIGHT} at {args.fps:g} fps, scan 10 Hz, pose 50 Hz, one headless Chromium")
    print(f"{'transport':<12}{'server CPU (one core)':>24}{'latency median':>18}{'p95':>10}{'drawn fps':>11}")
    for transport in ("websocket", "frames", "mjpeg"):
        r = measure(transport, args.seconds, args.fps)
        cpu = f"{100 * r['cpu_share']:.1f} %"
        if "latency_median_ms" in r:
            lat = f"{r['latency_median_ms']:.1f} ms", f"{r['latency_p95_ms']:.1f} ms", f"{r['drawn_fps']:.1f}"
        else:
            lat = ("-", "-", "-")
        print(f"{transport:<12}{cpu:>24}{lat[0]:>18}{lat[1]:>10}{lat[2]:>11}")
    print("goals: server CPU <= 15 % of one core; latency median <= 100 ms on loopback")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
