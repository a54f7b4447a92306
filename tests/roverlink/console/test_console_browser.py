"""The console in a real browser (Debian's headless Chromium, driven by Selenium) on an emulated
robot on the wall clock: what a user on a laptop does, checked against the emulator's truth.

Screenshots for docs/console.md are saved to build/console/.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest
from browser_support import (
    CHROMIUM,
    DRIVER,
    SHOTS,
    Steps,
    camera_truth,
    chromium,
    drag_on_camera,
    emulated_console,
    open_page,
    pose_x,
    shown_frame,
    until,
)

from roverlink.console_app import ConsoleRun

if not (CHROMIUM and DRIVER):
    if os.environ.get("ROVERLINK_REQUIRE_BROWSER"):
        raise RuntimeError("the console's browser tests need Debian's chromium and chromium-driver")
    pytest.skip("no chromium/chromedriver (Debian: apt install chromium chromium-driver)", allow_module_level=True)
pytest.importorskip("selenium.webdriver")


@pytest.fixture(scope="module")
def robot(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[ConsoleRun, Steps]]:
    with emulated_console(tmp_path_factory.mktemp("console")) as running:
        yield running


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    with chromium(1366, 768) as driver:  # a laptop's screen: the screenshots in docs/console.md
        yield driver


def test_the_page_loads_without_errors_and_the_camera_updates(robot: tuple[ConsoleRun, Steps], browser: Any) -> None:
    run, _ = robot
    open_page(browser, run)
    first = shown_frame(browser)
    until(lambda: shown_frame(browser) >= first + 3, what="the camera image updating")
    until(lambda: "points" in browser.find_element("id", "scan-info").text, what="the scan drawn")
    errors = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    assert errors == []
    SHOTS.mkdir(parents=True, exist_ok=True)
    browser.save_screenshot(str(SHOTS / "console.png"))


def test_a_box_drawn_on_the_picture_starts_tracking_the_target(robot: tuple[ConsoleRun, Steps], browser: Any) -> None:
    run, _ = robot
    hub, pilot = run.console.hub, run.console.pilot
    open_page(browser, run)
    shown = hub.frame(shown_frame(browser))
    assert shown is not None and shown.device_time_s is not None
    truth = camera_truth(run, shown.device_time_s)
    assert truth is not None, "the target is in the picture"
    x0, y0, x1, y1 = truth
    margin = 3
    drag_on_camera(browser, (x0 - margin, y0 - margin, x1 - x0 + 2 * margin, y1 - y0 + 2 * margin))
    until(lambda: pilot.has_target, what="a tracker started from the box")
    track = until(
        lambda: (t := pilot.follow.last_track) is not None and t.found and t.time_s > shown.time_s and t,
        what="the target tracked on a later frame",
    )
    tx, ty, tw, th = track.box
    cx, cy = tx + tw / 2, ty + th / 2
    assert x0 <= cx <= x1 and y0 <= cy <= y1, (track.box, truth)
    until(
        lambda: "tracking" in browser.execute_script("return JSON.stringify(view.overlay)"),
        what="the tracked box drawn on the page",
    )
    # Follow it from the page: the robot drives to it (the target stands 1.6 m ahead).
    start = pose_x(run)
    browser.find_element("id", "arm").click()
    browser.find_element("id", "follow").click()
    until(lambda: pilot.following and run.robot.armed, what="following, armed, from the page")
    until(lambda: pose_x(run) > start + 0.3, timeout_s=15, what="the robot driving to the target")
    assert pilot.mode not in ("teleop", "idle", "disarmed")
    until(lambda: "obstacle points" in browser.find_element("id", "scan-info").text, what="the scan drawn")
    browser.save_screenshot(str(SHOTS / "console-tracking.png"))
    browser.find_element("id", "unfollow").click()
    until(lambda: pilot.mode == "idle", what="following stopped from the page")
    browser.find_element("id", "disarm").click()
    until(lambda: not run.robot.armed, what="disarmed from the page")


def test_keyboard_teleop_drives_and_the_stop_button_disarms(robot: tuple[ConsoleRun, Steps], browser: Any) -> None:
    from selenium.webdriver.common.action_chains import ActionChains

    run, _ = robot
    open_page(browser, run)
    browser.find_element("id", "arm").click()
    until(lambda: run.robot.armed, what="armed from the page")
    body = browser.find_element("tag name", "body")
    start = pose_x(run)
    ActionChains(browser).key_down("w", body).perform()
    until(lambda: pose_x(run) > start + 0.05, what="driven forward by the W key")
    frame = shown_frame(browser)
    browser.find_element("id", "stop").click()
    until(lambda: not run.robot.armed, timeout_s=1.0, what="disarmed by STOP")
    ActionChains(browser).key_up("w", body).perform()
    until(lambda: shown_frame(browser) > frame + 2, what="the camera still streaming after STOP")
    until(lambda: run.console.pilot.mode == "disarmed", what="the pilot disarmed")
    # Disarmed stays disarmed: the loop does not re-arm it (watched over ten of its steps).
    steps = robot[1]
    seen = len(steps.log)
    until(lambda: len(steps.log) >= seen + 10, what="ten more control steps")
    assert not run.robot.armed


def test_the_on_screen_joystick_and_a_gamepad_drive_too(robot: tuple[ConsoleRun, Steps], browser: Any) -> None:
    from selenium.webdriver.common.action_chains import ActionChains

    run, _ = robot
    open_page(browser, run)
    browser.find_element("id", "arm").click()
    until(lambda: run.robot.armed, what="armed from the page")
    # The joystick: pressed and pushed up (forward), as a finger or the mouse does.
    start = pose_x(run)
    pad = browser.find_element("id", "joystick")
    ActionChains(browser).move_to_element(pad).click_and_hold().move_by_offset(0, -50).perform()
    until(lambda: pose_x(run) > start + 0.05, what="driven forward by the joystick")
    ActionChains(browser).release().perform()
    until(lambda: run.console.pilot.mode != "teleop", what="the joystick released")
    # A gamepad's left stick pushed forward (the Gamepad API, as a connected pad reports it).
    start = pose_x(run)
    browser.execute_script("navigator.getGamepads = () => [{ axes: [0, -0.9, 0, 0], buttons: [] }];")
    until(lambda: pose_x(run) > start + 0.05, what="driven forward by the gamepad")
    browser.execute_script("navigator.getGamepads = () => [{ axes: [0, 0, 0, 0], buttons: [] }];")
    until(lambda: run.console.pilot.mode != "teleop", what="the gamepad's stick centred")
    browser.find_element("id", "stop").click()
    until(lambda: not run.robot.armed, what="disarmed by STOP")


def test_the_obstacle_guard_has_its_line_and_the_override_is_held_on_the_page(
    robot: tuple[ConsoleRun, Steps], browser: Any
) -> None:
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.keys import Keys

    from host_sdk.autonomy import GuardState

    run, _ = robot
    pilot = run.console.pilot
    open_page(browser, run)
    browser.find_element("id", "arm").click()
    until(lambda: run.robot.armed, what="armed from the page")
    line, button = browser.find_element("id", "guard"), browser.find_element("id", "override")
    body = browser.find_element("tag name", "body")

    def guarded(*states: GuardState) -> bool:
        return pilot.guarded is not None and pilot.guarded.state in states

    ActionChains(browser).key_down("w", body).perform()  # protected: the guard's verdict on the line
    until(lambda: guarded(GuardState.CLEAR, GuardState.SLOWED, GuardState.STOPPED), what="W through the guard")
    until(lambda: line.text and "override" not in line.text, what="the guard's line")
    # The page's header stays on top while it scrolls: bring the button to the middle of the view first.
    browser.execute_script("arguments[0].scrollIntoView({block: 'center'})", button)
    ActionChains(browser).click_and_hold(button).perform()  # the button held: each command carries it
    until(lambda: guarded(GuardState.OVERRIDE), what="the override riding on the drive commands")
    assert "held" in button.get_attribute("class") and line.text.startswith("override held")
    ActionChains(browser).release().perform()  # let go: protected again with the next command
    until(lambda: guarded(GuardState.CLEAR, GuardState.SLOWED, GuardState.STOPPED), what="the guard back")
    assert "held" not in button.get_attribute("class") and not line.text.startswith("override held")
    ActionChains(browser).key_down(Keys.SHIFT).perform()  # Shift is the keyboard's override
    until(lambda: guarded(GuardState.OVERRIDE), what="Shift held")
    ActionChains(browser).key_up(Keys.SHIFT).key_up("w", body).perform()
    until(lambda: run.console.pilot.mode != "teleop", what="the key released")
    browser.find_element("id", "stop").click()
    until(lambda: not run.robot.armed, what="disarmed by STOP")


def test_a_closed_or_frozen_tab_stops_the_robot_within_the_command_lifetime(
    robot: tuple[ConsoleRun, Steps], browser: Any
) -> None:
    from selenium.webdriver.common.action_chains import ActionChains

    run, steps = robot
    lifetime = run.console.hub.command_lifetime_s
    period = run.loop.period_s
    open_page(browser, run)
    browser.find_element("id", "arm").click()
    until(lambda: run.robot.armed, what="armed from the page")

    def teleop_ends_after(action: Callable[[], None]) -> float:
        """Hold W until the robot drives, then `action`: seconds until the last teleop step."""
        body = browser.find_element("tag name", "body")
        ActionChains(browser).key_down("w", body).perform()
        until(lambda: run.console.pilot.mode == "teleop", what="driving from the page")
        acted = time.monotonic()
        action()
        until(lambda: run.console.pilot.mode != "teleop", timeout_s=3.0, what="teleop ended")
        ended = next(t for t, mode in reversed(steps.log) if mode == "teleop")
        return ended - acted

    def freeze() -> None:  # what Chrome does to a tab it freezes: its timers and handlers stop
        browser.execute_cdp_cmd("Page.setWebLifecycleState", {"state": "frozen"})

    # Frozen: the key is still down but no command comes; the last one lapses.
    assert teleop_ends_after(freeze) <= lifetime + 2 * period + 0.1
    browser.execute_cdp_cmd("Page.setWebLifecycleState", {"state": "active"})
    ActionChains(browser).key_up("w", browser.find_element("tag name", "body")).perform()
    assert run.robot.armed, "stopped by the lapsed command, not by a failsafe"

    # Closed: its WebSocket closes and the command is dropped at once. A second tab watches.
    driving_tab = browser.current_window_handle
    browser.switch_to.new_window("tab")
    open_page(browser, run)
    watcher = browser.current_window_handle
    browser.switch_to.window(driving_tab)
    until(
        lambda: browser.execute_script("return document.visibilityState") == "visible", what="the driving tab in front"
    )
    assert teleop_ends_after(browser.close) <= 3 * period + 0.2  # at once: not left to lapse
    browser.switch_to.window(watcher)
    assert "watching" in browser.find_element("id", "role").text


def test_a_hidden_tab_stops_driving(robot: tuple[ConsoleRun, Steps], browser: Any) -> None:
    """A tab put behind another (its timers slowed to once a second) stops the robot at once."""
    from selenium.webdriver.common.action_chains import ActionChains

    run, steps = robot
    open_page(browser, run)
    driving_tab = browser.current_window_handle
    browser.find_element("id", "arm").click()
    until(lambda: run.robot.armed, what="armed from the page")
    ActionChains(browser).key_down("w", browser.find_element("tag name", "body")).perform()
    until(lambda: run.console.pilot.mode == "teleop", what="driving from the page")
    browser.switch_to.new_window("tab")
    until(lambda: run.console.pilot.mode != "teleop", timeout_s=3.0, what="teleop ended")
    seen = len(steps.log)
    until(lambda: len(steps.log) >= seen + 30, what="30 more control steps")
    assert all(mode != "teleop" for _, mode in steps.log[seen:]), "driving again from a hidden tab"
    browser.close()
    browser.switch_to.window(driving_tab)
