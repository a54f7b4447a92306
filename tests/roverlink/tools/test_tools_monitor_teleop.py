"""`roverlink monitor` (read-only, plain and Textual) and `roverlink teleop` (keys, expiry), headless."""

from __future__ import annotations

import asyncio
import math
import time
from collections.abc import Callable

import pytest
from textual_pilot import hold as hold_keys
from textual_pilot import until

from emulator.firmware.statemachine import SessionState
from host_sdk import FeedbackSample, Robot
from roverlink.cli import main
from roverlink.commands.monitor import plain
from roverlink.dashboard import Dashboard, lines
from roverlink.teleop import TeleopController
from roverlink.tui import DashboardApp, TeleopApp
from tests.support.emulate import emulate

PROFILES = ["diffdrive-tb6612", "diffdrive-bts7960", "picar"]


@pytest.mark.parametrize("profile", PROFILES)
def test_plain_monitor_is_read_only(profile: str, capsys: pytest.CaptureFixture[str]) -> None:
    with Robot.connect(f"emu://{profile}?clock=virtual") as robot:
        dashboard = Dashboard(robot)
        assert plain(robot, dashboard, 0.5, 3.0) == 6
        states = {t[2] for t in robot.emulator.truth.firmware.transitions}
        assert SessionState.ARMED not in states
        assert robot.stats.setpoints_sent == 0
        text = "\n".join(lines(dashboard.snapshot()))
        name = robot.identity.robot_name
    out = capsys.readouterr().out
    assert out.count(" s  disarmed  v ") == 6
    assert name in text and "state DISARMED" in text
    assert "board  rx" in text and "rtt" in text and "(the monitor never commands)" in text


def test_monitor_command_with_live_view(capsys: pytest.CaptureFixture[str]) -> None:
    url = "emu://diffdrive-tb6612?clock=virtual"
    assert main(["monitor", url, "--plain", "--duration", "2", "--foxglove", "--foxglove-port", "0"]) == 0
    captured = capsys.readouterr()
    assert "live view: ws://127.0.0.1:" in captured.err
    assert "recorded" in captured.out and "/roverlink/feedback" in captured.out


def test_textual_monitor_headless() -> None:
    with emulate("--quiet", "--profile", "picar") as board, Robot.connect(board.url) as robot:
        app = DashboardApp(Dashboard(robot), hz=10)

        async def run() -> str:
            async with app.run_test() as pilot:
                ok = await until(lambda: "feedback" not in str(app.query_one("#motion").render()).lower(), pilot)
                assert ok
                await until(lambda: "board  rx" in str(app.query_one("#link").render()), pilot)
                text = "\n".join(str(app.query_one(f"#{w}").render()) for w in ("state", "motion", "link"))
                await pilot.press("q")
                return text

        text = asyncio.run(run())
        assert "AckermannPiCar" in text and "DISARMED" in text and "measured" in text and "board  rx" in text
        assert not robot.armed


@pytest.mark.parametrize("profile", PROFILES)
def test_teleop_drives_while_keys_arrive_and_stops_when_they_stop(profile: str) -> None:
    ackermann = profile == "picar"
    # A real pty and two processes on the wall clock: a 1 s watchdog, so a loaded test machine's
    # scheduling pauses are not taken for teleop's (test_teleop_commands_do_not_wait_for_a_stalled_ui
    # and the virtual-clock tests below hold teleop to the default watchdog).
    with emulate("--quiet", "--profile", profile) as board, Robot.connect(board.url, watchdog_s=1.0) as robot:
        controller = TeleopController(robot, key_timeout_s=0.4)
        app = TeleopApp(Dashboard(robot), controller)

        async def hold(pilot: object, *keys: str, done: Callable[[FeedbackSample], bool]) -> bool:
            """Press keys the way a held key repeats until a FEEDBACK shows `done` (a deadline of
            5 s: a loaded machine may answer late, a broken one never)."""
            seen: list[FeedbackSample] = []
            unsubscribe = robot.on_feedback(seen.append)
            try:
                return await hold_keys(pilot, keys, lambda: any(done(s) for s in seen))
            finally:
                unsubscribe()

        def why() -> str:
            return f"{robot!r} failsafe {robot.failsafe}, teleop: {controller.message!r} {controller.setpoint}"

        async def run() -> None:
            async with app.run_test() as pilot:
                await pilot.press("enter")
                # the PiCar's ESC window first; a refused arm leaves its reason in the message
                assert await until(lambda: robot.armed, pilot), controller.message
                n = 1 if ackermann else 2
                assert await hold(pilot, "up", done=lambda s: min(s.wheel_speeds_m_s[:n]) > 0.05), why()
                assert controller.setpoint is not None and controller.setpoint.linear_m_s > 0
                # Released: within the key timeout the target drops to zero and the robot stops, still armed.
                assert await until(lambda: max(abs(v) for v in robot.feedback.wheel_speeds_m_s) < 0.01, pilot)
                assert robot.armed and robot.failsafe is None, why()
                await pilot.press("plus")
                if ackermann:  # forward and left together: the servo steers left
                    assert await hold(pilot, "up", "left", done=lambda s: s.steering_rad > 0.2), why()
                else:  # left in place: the right wheel forward, the left back
                    turning = lambda s: s.wheel_speeds_m_s[1] > 0.05 and s.wheel_speeds_m_s[0] < -0.05  # noqa: E731
                    assert await hold(pilot, "left", done=turning), why()
                await pilot.press("space")
                await pilot.press("x")
                assert await until(lambda: not robot.armed, pilot)
                await pilot.press("q")

        asyncio.run(run())
        assert robot.failsafe is None


def test_teleop_controller_limits_and_expiry() -> None:
    with Robot.connect("emu://picar?clock=virtual") as robot:
        controller = TeleopController(robot, key_timeout_s=0.5, level=5)
        controller.key("up")
        controller.key("left")
        v, steer = controller.target(robot.now())
        assert v == pytest.approx(robot.config.max_wheel_speed_mm_s / 1000)
        assert steer == pytest.approx(math.radians(35))  # the servo's travel to the left (90 -> 125 deg)
        assert controller.target(robot.now() + 0.6) == (0.0, 0.0)
        controller.key("minus")
        assert "speed" in controller.message
        assert controller.key("z") is None


@pytest.mark.parametrize("profile", PROFILES)
def test_teleop_rides_out_a_busy_ui_but_not_a_dead_one(profile: str) -> None:
    """A UI that misses ticks for longer than the board's watchdog keeps the robot armed while a
    key is live (and at zero after); a program that stops for good still fails the robot safe."""
    with Robot.connect(f"emu://{profile}?clock=virtual") as robot:
        robot.arm()
        controller = TeleopController(robot, key_timeout_s=2.2 * robot.watchdog_s)
        controller.key("up")
        controller.tick()
        robot.sleep(2 * robot.watchdog_s)  # no tick: the UI is busy, the key still live
        assert robot.armed and robot.failsafe is None
        assert robot.feedback.wheel_speeds_m_s[0] > 0.02
        robot.sleep(0.4 * robot.watchdog_s)  # the key lapses: the SDK stops repeating it...
        controller.tick()  # ...and the next tick sends zero, held while the UI is busy again
        robot.sleep(2 * robot.watchdog_s)
        assert robot.armed and robot.failsafe is None
        assert max(abs(v) for v in robot.feedback.wheel_speeds_m_s) < 0.05
        controller.key("up")
        controller.tick()
        robot.sleep(controller.key_timeout_s + 2 * robot.watchdog_s)  # the program stopped
        assert not robot.armed


def test_teleop_commands_do_not_wait_for_a_stalled_ui() -> None:
    """The UI's event loop blocks (a slow terminal, a long render) right after a key is released:
    the controller's own thread still sends the zero, so the robot stops and stays armed."""
    with emulate("--quiet", "--profile", "diffdrive-tb6612") as board, Robot.connect(board.url) as robot:
        controller = TeleopController(robot, key_timeout_s=0.3)
        app = TeleopApp(Dashboard(robot), controller)

        async def run() -> None:
            async with app.run_test() as pilot:
                await pilot.press("enter")
                assert await until(lambda: robot.armed, pilot), controller.message
                await hold_keys(pilot, ("up",), lambda: robot.feedback.wheel_speeds_m_s[0] >= 0.05)
                assert robot.feedback.wheel_speeds_m_s[0] >= 0.05, controller.message
                # The stall: key lapse (0.3 s) + the board's watchdog, with no event-loop turn at all.
                time.sleep(controller.key_timeout_s + 3 * robot.watchdog_s)
                assert robot.armed and robot.failsafe is None, f"{robot!r} failsafe {robot.failsafe}"
                assert max(abs(v) for v in robot.feedback.wheel_speeds_m_s) < 0.05
                await pilot.press("q")

        asyncio.run(run())


def test_teleop_refuses_without_a_terminal(monkeypatch: pytest.MonkeyPatch) -> None:
    assert main(["teleop", "emu://"]) == 2
