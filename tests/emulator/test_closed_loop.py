"""The firmware's PID with the profiles' default gains on the profiles' plants: does it drive?"""

from __future__ import annotations

import math

import pytest

from emulator import Emulator
from host_sdk import enums, messages
from host_sdk.enums import Status
from tests.support.hostlink import Host


def _wait_out_esc_window(host: Host) -> None:
    """Keep the session alive (PING feeds the watchdog) until the ESC's arming window is over."""
    fw = host.emu.firmware
    assert fw is not None
    while fw.snapshot().esc_hold:
        host.send(messages.Ping(0))
        host.run(0.1)


def _mean_rim_speeds(emu: Emulator, host: Host, msg: messages.Message, seconds: float, lockstep: bool) -> list[float]:
    sums = [0.0] * len(emu.plant.units)
    n = 0
    for _ in range(round(seconds / 0.02)):
        host.send(msg)
        if lockstep:
            host.wait_for(messages.Feedback, 0.05)
        for _ in range(4):
            host.run(0.005)
            for i, w in enumerate(emu.truth.plant.wheels):
                sums[i] += w.rim_speed_mm_s
            n += 1
    return [s / n for s in sums]


@pytest.mark.parametrize(
    ("name", "left", "right"),
    [
        ("diffdrive-tb6612", 300, 300),
        ("diffdrive-tb6612", 150, 450),
        ("diffdrive-bts7960", 600, 600),
        ("diffdrive-bts7960", -300, 200),
    ],
)
def test_diff_drive_steady_state_within_2_percent(name: str, left: int, right: int) -> None:
    emu = Emulator(name, seed=11)
    host = Host(emu)
    lockstep = emu.profile.robot.feedback_mode is enums.FeedbackMode.LOCKSTEP
    host.session(mode=emu.profile.robot.feedback_mode)
    msg = messages.SetWheelSpeeds(left, right)
    host.drive(msg, 2.0, lockstep)
    speeds = _mean_rim_speeds(emu, host, msg, 1.0, lockstep)
    assert speeds[0] == pytest.approx(left, rel=0.02)
    assert speeds[1] == pytest.approx(right, rel=0.02)
    # The firmware sees it too (feedback = encoder-measured speeds), without saturating.
    fb = host.of(messages.Feedback)[-1]
    assert not fb.status & Status.SATURATED
    assert abs(fb.wheel_speed_mm_s[0] - left) < 40 and abs(fb.wheel_speed_mm_s[1] - right) < 40


def test_ackermann_speed_within_2_percent_and_turning_radius_from_the_wire() -> None:
    emu = Emulator("picar", seed=12)
    host = Host(emu)
    host.session()
    _wait_out_esc_window(host)
    steer_mrad = round(math.radians(15) * 1000)
    msg = messages.SetAckermann(1000, steer_mrad)
    host.drive(msg, 2.0, lockstep=False)
    theta0, dist0 = emu.truth.plant.theta_rad, emu.truth.plant.distance_m
    speeds = _mean_rim_speeds(emu, host, msg, 2.0, lockstep=False)
    assert speeds[0] == pytest.approx(1000, rel=0.02)
    truth = emu.truth.plant
    radius = (truth.distance_m - dist0) / (truth.theta_rad - theta0)
    fb = host.of(messages.Feedback)[-1]
    assert fb.steering_mrad == steer_mrad  # 15 degrees is on the 15-degree grid: reported back as sent
    assert radius == pytest.approx(emu.profile.robot.wheelbase_m / math.tan(fb.steering_mrad / 1000), rel=0.03)


def test_steering_is_quantised_and_reported_back() -> None:
    emu = Emulator("picar", seed=13)
    host = Host(emu)
    host.session()
    reported = {}
    for deg in (-40, -20, -7, 8, 20, 40):
        host.send(messages.SetAckermann(0, round(math.radians(deg) * 1000)))
        host.run(0.05)
        reported[deg] = round(math.degrees(host.of(messages.Feedback)[-1].steering_mrad / 1000))
    # servo 65..125 deg, centre 90, 15-degree steps: -25 (clamped), -15, 0, +15, +30 (120 deg)
    assert reported == {-40: -25, -20: -15, -7: 0, 8: 15, 20: 15, 40: 30}
    host.drive(messages.SetAckermann(0, 1571), 0.3, lockstep=False)
    assert emu.truth.plant.servo_deg == pytest.approx(120.0)  # the horn followed, within its slew rate
    emu.cut_link()
    host.run(0.5)  # watchdog (250 ms): FAILSAFE puts the steering back to its centre
    assert emu.truth.plant.servo_deg == pytest.approx(90.0)


def test_effort_limit_saturates_and_is_reported() -> None:
    emu = Emulator("picar", seed=14)
    host = Host(emu)
    host.session()
    _wait_out_esc_window(host)
    host.drive(messages.SetAckermann(2000, 0), 2.0, lockstep=False)  # more than 600 permille can give
    fb = host.of(messages.Feedback)[-1]
    assert fb.status & Status.SATURATED and fb.effort_permille[0] == 600
    assert 1000 < emu.truth.plant.speed_m_s * 1000 < 1900


def _toggles_over(emu: Emulator, host: Host, msg: messages.SetWheelSpeeds | None, seconds: float) -> list[int]:
    before = emu.truth.plant.led_toggles
    for _ in range(round(seconds / 0.02)):
        if msg is not None:
            host.send(msg)
        host.run(0.02)
    return [b - a for a, b in zip(before, emu.truth.plant.led_toggles, strict=True)]


def test_turn_signals_follow_motion_state() -> None:
    emu = Emulator("diffdrive-tb6612", seed=15)
    host = Host(emu)
    host.session(arm=False)
    host.send(messages.Ping(0))
    # DISARMED: the front pair and the rear pair alternate at 1.5 Hz: each LED changes 6 times in 2 s.
    assert all(5 <= n <= 7 for n in _toggles_over(emu, host, None, 2.0))
    assert isinstance(host.arm(), messages.Ack)
    patterns = {
        "left turn": (messages.SetWheelSpeeds(100, 300), lambda t: t[0] >= 5 and t[2] >= 5 and t[1] == t[3] == 0),
        "right turn": (messages.SetWheelSpeeds(300, 100), lambda t: t[1] >= 5 and t[3] >= 5 and t[0] == t[2] == 0),
        "spin in place": (messages.SetWheelSpeeds(-200, 200), lambda t: all(n >= 5 for n in t)),
        "straight back": (messages.SetWheelSpeeds(-200, -200), lambda t: t == [0, 0, 0, 0]),
    }
    for name, (msg, expected) in patterns.items():
        _toggles_over(emu, host, msg, 0.7)  # one blink period to settle into the pattern
        toggles = _toggles_over(emu, host, msg, 2.0)
        assert expected(toggles), (name, toggles)
    emu.cut_link()
    host.run(0.5)  # watchdog: FAILSAFE
    assert all(10 <= n <= 14 for n in _toggles_over(emu, host, None, 2.0))  # all four at 3 Hz


def test_turn_signals_light_at_boot_not_at_the_first_tick() -> None:
    # Found by tests/system/conformance (test_turn_signal_leds): the C++ core lights the IDLE pattern at the
    # end of begin(); the model waited for the first control tick, 10 ms (here 14: the boot's
    # EEPROM write delays it) later.
    emu = Emulator("diffdrive-tb6612", seed=16)
    assert emu.run_until(lambda: emu.firmware is not None, 1.0, step_us=100)
    assert emu.firmware is not None and emu.firmware.tick_count == 0
    assert emu.truth.plant.leds == {"front_left": True, "front_right": True, "rear_left": False, "rear_right": False}
