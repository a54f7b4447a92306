"""Who drives, in a real browser (headless Chromium) on "a robot" (the board and the sensors served on
ptys by `roverlink emulate`): following lasts while the driving tab keeps it alive (a frozen or
closed tab ends it and the car stops within one command lifetime), a watcher takes the wheel and the
driver is told; on a laptop's 1366x768 screen the status and the main buttons are in view, a hung
board shows as a banner and a refusal stays until it is dismissed.

Screenshots for docs/console.md are saved to build/console/.
"""

from __future__ import annotations

import os
import signal
import time
from collections.abc import Iterator
from typing import Any

import pytest
from browser_support import CHROMIUM, DRIVER, SHOTS, Steps, chromium, open_page, pty_console, until

from roverlink.console_app import ConsoleRun
from tests.support.emulate import EmulatorProcess

if not (CHROMIUM and DRIVER):
    if os.environ.get("ROVERLINK_REQUIRE_BROWSER"):
        raise RuntimeError("the console's browser tests need Debian's chromium and chromium-driver")
    pytest.skip("no chromium/chromedriver (Debian: apt install chromium chromium-driver)", allow_module_level=True)
pytest.importorskip("selenium.webdriver")

LAPTOP = (1366, 768)
Robot = tuple[ConsoleRun, Steps, EmulatorProcess]


@pytest.fixture(scope="module")
def robot() -> Iterator[Robot]:
    with pty_console() as running:
        yield running


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    with chromium(*LAPTOP) as driver:
        yield driver


def click(browser: Any, element_id: str) -> None:
    browser.find_element("id", element_id).click()


def choose_target(browser: Any, run: ConsoleRun) -> None:
    """Target: person. Nobody is in the emulated room: the follow behaviour searches for one, and drives."""
    click(browser, "target-person")
    until(lambda: run.console.pilot.has_target, what="a person targeted")


def follow(browser: Any, run: ConsoleRun) -> None:
    pilot = run.console.pilot
    click(browser, "arm")
    click(browser, "follow")
    try:
        until(
            lambda: pilot.following and run.robot.armed and pilot.mode not in ("idle", "disarmed"),
            what="following, armed, from the page",
        )
    except AssertionError as exc:
        raise AssertionError(f"{exc}: {pilot.mode}, {run.supervisor.health()}") from None


def ended_after(run: ConsoleRun, steps: Steps, action: Any) -> float:
    """Do `action`; the time from the last sign of the driving page (its keep-alive, or the action
    itself) to the first control step that no longer followed. The control loop's own steps time
    it, so a busy machine's late steps count as late, and nothing else does."""
    acted = time.monotonic()
    action()
    ended = until(
        lambda: next((t for t, on in steps.following if t > acted and not on), None),
        timeout_s=10,
        what="following ended",
    )
    last_alive = run.console.hub.alive_s  # -inf once the page closed: then the action is the last sign
    heard = last_alive if last_alive > acted - 1.0 else acted
    late = [t for t, on in steps.following if heard < t < ended]  # the steps that still followed
    return (late[-1] if late else heard) - heard


def test_following_ends_when_the_driving_tab_freezes_or_closes(robot: Robot, browser: Any) -> None:
    run, steps, _ = robot
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


def test_a_watcher_takes_the_wheel_and_the_driver_is_told(robot: Robot, browser: Any) -> None:
    from selenium.webdriver.common.action_chains import ActionChains

    run, _, _ = robot
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
    return bool(
        browser.execute_script(
            "const r = document.getElementById(arguments[0]).getBoundingClientRect();"
            "return r.height > 0 && r.top >= 0 && r.bottom <= window.innerHeight && r.right <= window.innerWidth;",
            element_id,
        )
    )


def test_on_a_laptop_screen_a_lost_link_and_a_refusal_are_in_view_until_dismissed(robot: Robot, browser: Any) -> None:
    run, steps, board = robot
    open_page(browser, run)
    assert browser.execute_script("return window.scrollY") == 0
    for element in ("armed", "link", "arm", "follow", "stop", "status"):
        assert in_view(browser, element), element
    rows = browser.find_element("id", "status").text
    assert "armed" in rows and "link" in rows and "feedback" in rows
    until(lambda: "points" in browser.find_element("id", "scan-info").text, timeout_s=30, what="the scan drawn")
    SHOTS.mkdir(parents=True, exist_ok=True)
    browser.save_screenshot(str(SHOTS / "console-laptop.png"))  # docs/images/console.png

    os.kill(board.proc.pid, signal.SIGSTOP)  # the board hangs: it answers nothing
    try:
        hung(browser)
    finally:
        os.kill(board.proc.pid, signal.SIGCONT)
    until(lambda: "board: link up" in browser.find_element("id", "link").text, timeout_s=20, what="the link back")
    seen = len(steps.log)
    until(lambda: len(steps.log) >= seen + 100, timeout_s=30, what="a hundred more control steps")
    assert "ARM" in browser.find_element("id", "errors").text, "the refusal went away by itself"
    while "ARM" in browser.find_element("id", "errors").text:  # dismissed one by one
        browser.find_element("css selector", "#errors li button").click()
    until(lambda: all(r.what != "ARM" for r in run.supervisor.health().refusals), what="dismissed for every page")


def hung(browser: Any) -> None:
    """While the board answers nothing: the banner, armed: no, Arm refused, all of it in view."""
    until(lambda: "link lost since" in browser.find_element("id", "banner").text, what="the banner")
    assert "armed: no" in browser.find_element("id", "armed").text
    assert "lost" in browser.find_element("id", "link").text
    click(browser, "arm")  # refused: nobody answers
    until(lambda: "ARM" in browser.find_element("id", "errors").text, what="the refusal shown")
    for element in ("banner", "errors", "armed", "link", "arm", "status"):
        assert in_view(browser, element), element
    stale = browser.execute_script("return [...document.querySelectorAll('#status tr.stale')].map(r => r.textContent)")
    assert any("feedback" in row for row in stale), f"the feedback rate marked stale: {stale}"
    browser.save_screenshot(str(SHOTS / "console-link-lost.png"))


def test_a_page_that_cannot_reach_the_console_says_so_and_greys_what_it_shows(robot: Robot, browser: Any) -> None:
    """Last: the console's server goes (the Wi-Fi drops, the process ends)."""
    run, _, _ = robot
    open_page(browser, run)
    until(lambda: "board: link up" in browser.find_element("id", "link").text, what="the page up to date")
    run.console.server.close()
    until(lambda: "console unreachable since" in browser.find_element("id", "banner").text, what="the banner")
    assert "armed: ?" in browser.find_element("id", "armed").text and in_view(browser, "banner")
    rows = browser.execute_script("return [...document.querySelectorAll('#status tr')].map(r => r.className)")
    assert rows and all(kind == "stale" for kind in rows), rows
