"""What the console's browser tests share: the emulated robot in a small world on the wall clock
(its control loop on a thread, each step's mode logged), Debian's headless Chromium driven by
Selenium, and a user's gestures on the page (open it, drag a box on the picture)."""

from __future__ import annotations

import shutil
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from roverlink.console_app import EMULATED_LOST_AFTER_S, ConsoleRun, ConsoleSettings, start_emulated, start_robot
from roverlink.follow.app import RobotPorts
from tests.support.emulate import EmulatorProcess, emulate
from tests.support.wait import wait_until

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
DRIVER = shutil.which("chromedriver")
SHOTS = Path(__file__).resolve().parents[3] / "build" / "console"

WORLD = """
[world]
name = "console"
size_m = [5.0, 4.0]
wall_height_m = 0.5

[start]
x_m = 1.0
y_m = 2.0
theta_deg = 0.0

[[boxes]]
center = [3.2, 3.2]
size = [0.5, 0.4]
height_m = 0.4
colour = "#a05a2c"

[target]
radius_m = 0.12
height_m = 0.3
speed_m_s = 0.0
path = [[2.6, 1.9]]
"""


def until(check: Callable[[], Any], timeout_s: float = 10.0, what: str = "condition") -> Any:
    return wait_until(check, timeout_s, what, poll_s=0.02)


class Steps:
    """What the control loop did, step by step: (monotonic time, mode), and whether it was following."""

    def __init__(self, run: ConsoleRun) -> None:
        self.run = run
        self.log: list[tuple[float, str]] = []
        self.following: list[tuple[float, bool]] = []

    def __call__(self) -> None:
        now, pilot = time.monotonic(), self.run.console.pilot
        self.log.append((now, pilot.mode))
        self.following.append((now, pilot.following))


@contextmanager
def emulated_console(world_dir: Path, **settings: Any) -> Iterator[tuple[ConsoleRun, Steps]]:
    """The console on the emulated robot in WORLD, its loop running on a thread."""
    world = world_dir / "world.toml"
    world.write_text(WORLD)
    # The emulator shares this process with the robot program, the server and the tests, on a
    # machine that also runs the browser: a 1 s watchdog keeps a loaded machine's scheduling from
    # failing safe. The page's commands live as long (the bounds below follow it).
    run = start_emulated(
        "diffdrive-tb6612", world, ConsoleSettings(port=0, **settings), camera_fps=10.0, watchdog_s=1.0
    )
    steps = Steps(run)
    loop = threading.Thread(target=run.run, kwargs={"on_step": steps}, daemon=True)
    loop.start()
    try:
        yield run, steps
    finally:
        run.close()
        loop.join(timeout=10)


@contextmanager
def pty_console(**settings: Any) -> Iterator[tuple[ConsoleRun, Steps, EmulatorProcess]]:
    """The console on "a robot": the board served on a pty by a `roverlink emulate` of its own (light:
    it keeps pace on a busy machine), the lidar and camera by another; the console in this process,
    its loop on a thread. Yields the run, its steps and the board's process (to hang it: SIGSTOP)."""
    profile = ("--profile", "diffdrive-tb6612")
    sensors_args = (*profile, "--world", "random:1", "--lidar", "rplidar-a1", "--camera", "--quiet")
    with emulate(*profile, "--eeprom", "saved", "--quiet") as board, emulate(*sensors_args, devices=2) as sensors:
        ports = RobotPorts(board.url, sensors.devices["lidar"][-1], sensors.devices["camera"][-1])
        # The browser shares the busy machine too: FEEDBACK pauses that long are its scheduling, not a
        # lost link (these tests are about who drives; test_console_ride_through keeps the default).
        chosen = ConsoleSettings(port=0, watchdog_s=1.0, lost_after_s=EMULATED_LOST_AFTER_S, **settings)
        run = start_robot(ports, "diffdrive-tb6612", chosen)
        steps = Steps(run)
        loop = threading.Thread(target=run.run, kwargs={"on_step": steps}, daemon=True)
        loop.start()
        try:
            yield run, steps, board
        finally:
            run.close()
            loop.join(timeout=10)


@contextmanager
def chromium(width: int = 1280, height: int = 1000) -> Iterator[Any]:
    """Headless Chromium showing a `width` x `height` page."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    for arg in (
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-dev-shm-usage",
        f"--window-size={width},{height}",
    ):
        options.add_argument(arg)
    options.binary_location = CHROMIUM
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(DRIVER), options=options)
    try:
        yield driver
    finally:
        driver.quit()


def shown_frame(browser: Any) -> int:
    return int(browser.execute_script("return Number(document.body.dataset.frame || 0)"))


def open_page(browser: Any, run: ConsoleRun) -> None:
    browser.get(run.console.url)
    until(lambda: shown_frame(browser) > 0, timeout_s=30, what="a camera frame on the page")


def camera_truth(run: ConsoleRun, device_time_s: float) -> tuple[int, int, int, int] | None:
    """The target's pixels (x0, y0, x1, y1) in the frame the emulated camera took at that time."""
    assert run.emulated is not None
    device = run.emulated.emulator.sensors.devices["camera"]
    for truth in list(device.truth.values()):
        if abs(truth.time_us / 1e6 - device_time_s) < 1e-4:
            return truth.target_bbox  # type: ignore[no-any-return]
    return None


def drag_on_camera(browser: Any, box: tuple[float, float, float, float]) -> None:
    """Drag a box (image pixels x, y, w, h) on the camera canvas, as a user does with the mouse."""
    from selenium.webdriver.common.action_chains import ActionChains

    canvas = browser.find_element("id", "camera")
    scale = canvas.rect["width"] / int(canvas.get_attribute("width"))
    cx, cy = canvas.rect["width"] / 2, canvas.rect["height"] / 2
    x, y, w, h = box
    chain = ActionChains(browser)
    chain.move_to_element_with_offset(canvas, round(x * scale - cx), round(y * scale - cy)).click_and_hold()
    chain.move_by_offset(round(w * scale / 2), round(h * scale / 2))
    chain.move_by_offset(round(w * scale / 2), round(h * scale / 2)).release().perform()


def pose_x(run: ConsoleRun) -> float:
    """The robot's odometry x as the page is shown it."""
    return float(run.console.hub.latest()[3]["pose"]["x"])
