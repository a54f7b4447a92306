"""Who drives, in a real browser (headless Chromium) on the emulated robot: following lasts while the
driving tab keeps it alive (a frozen or closed tab ends it and the car stops within one command
lifetime), a watcher takes the wheel and the driver is told; on a laptop's 1366x768 screen the
status is in view, a lost link shows as a banner and a refusal stays until it is dismissed.

Screenshots for docs/console.md are saved to build/console/.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
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
    shown_frame,
    until,
)

from roverlink.console_app import ConsoleRun

if not (CHROMIUM and DRIVER):
    if os.environ.get("ROVERLINK_REQUIRE_BROWSER"):
        raise RuntimeError("the console's browser tests need Debian's chromium and chromium-driver")
    pytest.skip("no chromium/chromedriver (Debian: apt install chromium chromium-driver)", allow_module_level=True)
pytest.importorskip("selenium.webdriver")

LAPTOP = (1366, 768)


@pytest.fixture(scope="module")
def robot(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[ConsoleRun, Steps]]:
    with emulated_console(tmp_path_factory.mktemp("console")) as running:
        yield running


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    with chromium(*LAPTOP) as driver:
        yield driver


def click(browser: Any, element_id: str) -> None:
    browser.find_element("id", element_id).click()


def choose_target(browser: Any, run: ConsoleRun) -> None:
    """Drag a box round the target where the emulator's truth says it is on the frame shown."""
    shown = run.console.hub.frame(shown_frame(browser))
    assert shown is not None and shown.device_time_s is not None
    truth = camera_truth(run, shown.device_time_s)
    assert truth is not None, "the target is in the picture"
    x0, y0, x1, y1 = truth
    drag_on_camera(browser, (x0 - 3, y0 - 3, x1 - x0 + 6, y1 - y0 + 6))
    until(lambda: run.console.pilot.has_target, what="a tracker started from the box")


def follow(browser: Any, run: ConsoleRun) -> None:
    pilot = run.console.pilot
    click(browser, "arm")
    click(browser, "follow")
    until(lambda: pilot.following and run.robot.armed and pilot.mode not in ("idle", "disarmed"),
          what="following, armed, from the page")  # fmt: skip


def ended_after(run: ConsoleRun, steps: Steps, action: Any) -> float:
    """Do `action`; the time from the last sign of the driving page (its keep-alive, or the action
    itself) to the first control step that no longer followed. The control loop's own steps time
    it, so a busy machine's late steps count as late, and nothing else does."""
    acted = time.monotonic()
    action()
    ended = until(lambda: next((t for t, on in steps.following if t > acted and not on), None), timeout_s=10,
                  what="following ended")  # fmt: skip
    last_alive = run.console.hub.alive_s  # -inf once the page closed: then the action is the last sign
    heard = last_alive if last_alive > acted - 1.0 else acted
    late = [t for t, on in steps.following if heard < t < ended]  # the steps that still followed
    return (late[-1] if late else heard) - heard


def test_following_ends_when_the_driving_tab_freezes_or_closes(robot: tuple[ConsoleRun, Steps], browser: Any) -> None:
    run, steps = robot
    pilot, lifetime, period = run.console.pilot, run.console.hub.command_lifetime_s, run.loop.period_s
    open_page(browser, run)
    choose_target(browser, run)
    follow(browser, run)

    # Frozen (what Chrome does to a tab it freezes: its timers stop): the keep-alive lapses, and no
    # step follows more than one command lifetime after the page was last heard.
    freeze = {"state": "frozen"}
    took = ended_after(run, steps, lambda: browser.execute_cdp_cmd("Page.setWebLifecycleState", freeze))
    assert took <= lifetime + period, took
    assert "keeping it alive" in pilot.ended
    stopped = len(steps.log)
    until(lambda: len(steps.log) >= stopped + 5, what="five more control steps")
    assert all(mode in ("idle", "disarmed") for _, mode in steps.log[stopped + 1 :])  # the car stands
    browser.execute_cdp_cmd("Page.setWebLifecycleState", {"state": "active"})
    seen = len(steps.log)
    until(lambda: len(steps.log) >= seen + 10, what="ten more control steps")
    assert not pilot.following, "following came back by itself with the tab"

    # Closed: its WebSocket closes and following ends at once. A second tab watches.
    driving = browser.current_window_handle
    browser.switch_to.new_window("tab")
    open_page(browser, run)
    watcher = browser.current_window_handle
    browser.switch_to.window(driving)
    until(lambda: browser.execute_script("return document.visibilityState") == "visible", what="the driver in front")
    follow(browser, run)
    assert ended_after(run, steps, browser.close) <= lifetime
    browser.switch_to.window(watcher)
    until(lambda: "following no" in browser.find_element("id", "status").text, what="the watcher shown it ended")
    click(browser, "stop")
    until(lambda: not run.robot.armed, what="disarmed by STOP")


def test_a_watcher_takes_the_wheel_and_the_driver_is_told(robot: tuple[ConsoleRun, Steps], browser: Any) -> None:
    from selenium.webdriver.common.action_chains import ActionChains

    run, _ = robot
    open_page(browser, run)
    driver_tab = browser.current_window_handle
    click(browser, "arm")
    until(lambda: "driving" in browser.find_element("id", "role").text, what="the first tab driving")
    until(lambda: run.robot.armed, what="armed from the first tab")
    browser.switch_to.new_window("tab")
    open_page(browser, run)
    assert "watching" in browser.find_element("id", "role").text
    take = browser.find_element("id", "take")
    assert take.is_displayed()
    take.click()
    until(lambda: "driving" in browser.find_element("id", "role").text, what="the watcher driving")
    assert not take.is_displayed()
    ActionChains(browser).key_down("w", browser.find_element("tag name", "body")).perform()
    until(lambda: run.console.pilot.mode == "teleop", what=f"driven by the new driver ({run.console.pilot.mode})")
    ActionChains(browser).key_up("w", browser.find_element("tag name", "body")).perform()
    browser.close()
    browser.switch_to.window(driver_tab)
    until(lambda: "took the wheel" in browser.find_element("id", "errors").text, what="the old driver told")
    assert "watching" in browser.find_element("id", "role").text
    click(browser, "stop")
    until(lambda: not run.robot.armed, what="disarmed by STOP")


def in_view(browser: Any, element_id: str) -> bool:
    return bool(browser.execute_script(
        "const r = document.getElementById(arguments[0]).getBoundingClientRect();"
        "return r.height > 0 && r.top >= 0 && r.bottom <= window.innerHeight && r.right <= window.innerWidth;",
        element_id))  # fmt: skip


def test_on_a_laptop_screen_a_lost_link_and_a_refusal_are_in_view_until_dismissed(
    robot: tuple[ConsoleRun, Steps], browser: Any
) -> None:
    run, steps = robot
    assert run.emulated is not None
    open_page(browser, run)
    assert browser.execute_script("return window.scrollY") == 0
    for element in ("armed", "link", "stop", "status"):
        assert in_view(browser, element), element
    rows = browser.find_element("id", "status").text
    assert "armed" in rows and "link" in rows and "feedback" in rows
    SHOTS.mkdir(parents=True, exist_ok=True)
    browser.save_screenshot(str(SHOTS / "console-laptop.png"))

    with run.robot.transport.locked():  # the emulator runs on the robot's I/O thread
        run.emulated.emulator.cut_link()
    until(lambda: "link lost since" in browser.find_element("id", "banner").text, what="the banner")
    assert "armed: no" in browser.find_element("id", "armed").text
    assert "lost" in browser.find_element("id", "link").text
    click(browser, "arm")  # refused: nobody answers
    until(lambda: "ARM" in browser.find_element("id", "errors").text, what="the refusal shown")
    for element in ("banner", "errors", "armed", "link", "status"):
        assert in_view(browser, element), element
    stale = browser.find_elements("css selector", "#status tr.stale")
    assert any("feedback" in row.text for row in stale), "the feedback rate marked stale"
    browser.save_screenshot(str(SHOTS / "console-link-lost.png"))

    with run.robot.transport.locked():
        run.emulated.emulator.restore_link()
    until(lambda: "failsafe" in browser.find_element("id", "banner").text or
          browser.find_element("id", "banner").get_attribute("hidden") is not None, what="the link back")  # fmt: skip
    seen = len(steps.log)
    until(lambda: len(steps.log) >= seen + 100, timeout_s=30, what="a hundred more control steps")
    assert "ARM" in browser.find_element("id", "errors").text, "the refusal went away by itself"
    browser.find_element("css selector", "#errors li button").click()
    until(lambda: "ARM" not in browser.find_element("id", "errors").text, what="the refusal dismissed")
