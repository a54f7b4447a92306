"""The Robot API against the emulator on a virtual clock: validation, config, failsafe, resets, closing.

Uses the `robot` and `emulator` fixtures of the roverlink pytest plugin (host_sdk.testing.pytest_plugin).
"""

from __future__ import annotations

import itertools
import math
import os
import threading
import time
from typing import Any

import numpy as np
import pytest

import host_sdk
from emulator.firmware.statemachine import SessionState
from host_sdk import PROFILES, Robot, enums, messages
from host_sdk.errors import (
    CommandRangeError,
    ConnectTimeoutError,
    FailsafeError,
    FeedbackTimeoutError,
    IncompatibleFirmwareError,
    NackError,
    NotArmedError,
    RobotClosedError,
    SessionResetError,
    UnsupportedError,
)
from host_sdk.framing import Frame, FrameDecoder, encode_frame
from host_sdk.profiles import steering_angles
from host_sdk.transport import Transport
from protocol.generated.constants import PROTOCOL_VERSION

TICK_S = 0.01


def drive_for(robot: Robot, seconds: float, linear: float, angular: float = 0.0) -> None:
    end = robot.now() + seconds
    while robot.now() < end:
        robot.drive(linear, angular)
        robot.sleep(0.02)


# -- bad input ----------------------------------------------------------------------------------------
@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_non_finite_speeds_are_refused_naming_the_argument(roverlink_robot: Robot, value: float) -> None:
    roverlink_robot.arm()
    with pytest.raises(CommandRangeError) as err:
        roverlink_robot.drive(0.1, value)
    assert err.value.argument == "angular_rad_s" and "finite" in str(err.value)
    with pytest.raises(CommandRangeError, match="left_m_s"):
        roverlink_robot.set_wheel_speeds(value, 0.0)


def test_speed_over_the_configured_limit_raises_or_clamps_when_asked(
    roverlink_robot: Robot, roverlink_emulator: Any
) -> None:
    roverlink_robot.arm()
    with pytest.raises(CommandRangeError) as err:
        roverlink_robot.drive(0.8, 0.0)
    assert err.value.argument == "linear_m_s" and "0.6" in err.value.allowed and "clamp=True" in str(err.value)
    with pytest.raises(CommandRangeError, match=r"angular_rad_s = 4.0 .* -2.000..2.000 rad/s"):
        roverlink_robot.drive(0.4, 4.0)
    roverlink_robot.drive(0.8, 2.0, clamp=True)  # both wheels scaled by one factor: curvature kept
    roverlink_robot.sleep(0.05)
    targets = roverlink_emulator.truth.firmware.targets_mm_s
    assert max(abs(t) for t in targets) == 600
    assert (targets[1] - targets[0]) / ((targets[0] + targets[1]) / 2) == pytest.approx(2.0 * 0.2 / 0.8, rel=0.01)


@pytest.mark.roverlink(profile="picar")
def test_ackermann_steering_limits_and_unsupported_calls(roverlink_robot: Robot) -> None:
    roverlink_robot.arm(wait_esc=False)
    with pytest.raises(CommandRangeError) as err:
        roverlink_robot.drive_ackermann(0.5, 0.9)
    assert err.value.argument == "steering_rad" and "-0.436..0.611" in err.value.allowed
    with pytest.raises(CommandRangeError, match="cannot turn in place"):
        roverlink_robot.drive(0.0, 1.0)
    with pytest.raises(UnsupportedError, match="set_wheel_speeds"):
        roverlink_robot.set_wheel_speeds(0.1, 0.1)
    roverlink_robot.drive_ackermann(0.5, 0.9, clamp=True)


@pytest.mark.roverlink(profile="picar")
def test_steering_angles_are_the_angles_the_servo_reaches(roverlink_robot: Robot) -> None:
    """Whatever angle is asked for, the firmware puts its coarse servo on one of `steering_angles`
    (the PiCar's: -25, -15, 0, 15, 30 degrees), and every one of them is reached."""
    angles = steering_angles(roverlink_robot.config)
    assert [round(math.degrees(a)) for a in angles] == [-25, -15, 0, 15, 30]
    roverlink_robot.arm(wait_esc=False)
    reached = set()
    for asked in np.linspace(-0.6, 0.6, 25):
        roverlink_robot.drive_ackermann(0.1, float(asked), clamp=True)
        roverlink_robot.sleep(0.05)
        sample = roverlink_robot.wait_feedback()
        assert sample.steering_rad is not None
        assert min(abs(sample.steering_rad - a) for a in angles) < 0.002, asked
        reached.add(min(range(len(angles)), key=lambda i: abs(sample.steering_rad - angles[i])))
    assert reached == set(range(len(angles)))


def test_calls_on_a_closed_robot_raise(roverlink_robot: Robot) -> None:
    roverlink_robot.close()
    roverlink_robot.close()  # idempotent
    for call in (
        lambda: roverlink_robot.drive(0, 0),
        roverlink_robot.arm,
        lambda: roverlink_robot.identity,
        roverlink_robot.wait_feedback,
        roverlink_robot.read_config,
    ):
        with pytest.raises(RobotClosedError):
            call()


def test_drive_before_arm_says_to_arm(roverlink_robot: Robot) -> None:
    with pytest.raises(NotArmedError, match=r"robot.arm\(\)"):
        roverlink_robot.drive(0.1, 0.0)


# -- identity, config, PID ------------------------------------------------------------------------------
def test_identity_config_and_pid(roverlink_robot: Robot) -> None:
    ident = roverlink_robot.identity
    assert ident.robot_name == "DiffDriveTB6612" and ident.can(enums.Capability.DIFF_DRIVE)
    assert ident.watchdog_ms == 250 and ident.version == host_sdk.__version__
    assert roverlink_robot.config.max_wheel_speed_mm_s == 600
    new = roverlink_robot.set_config(max_wheel_speed_mm_s=400, safe_state=enums.SafeState.RAMP_DOWN)
    assert new.max_wheel_speed_mm_s == 400 and roverlink_robot.config == new
    roverlink_robot.arm()
    with pytest.raises(CommandRangeError, match=r"0\.4"):
        roverlink_robot.drive(0.5, 0.0)
    gains = roverlink_robot.set_pid(kp=2.0)
    assert gains.kp == 2.0 and gains.kf == PROFILES["diffdrive-tb6612"].pid.kf
    assert roverlink_robot.pid(1).kp == 2.0  # wheel=None set every wheel
    assert (
        roverlink_robot.set_pid(ks=40.0, wheel=1).ks == 40.0
        and roverlink_robot.pid(0).ks == PROFILES["diffdrive-tb6612"].pid.ks
    )
    with pytest.raises(CommandRangeError) as err:
        roverlink_robot.set_pid(ks=-5.0)
    assert err.value.argument == "ks" and "1000" in err.value.allowed
    # The board keeps f32 (0.62 is 0.6200000047683716 there); the gains read back as they were set.
    assert roverlink_robot.set_pid(kf=0.62, kp=0.1).kf == 0.62 and roverlink_robot.pid(0).kp == 0.1


def test_config_errors_name_the_field(roverlink_robot: Robot) -> None:
    with pytest.raises(CommandRangeError) as err:
        roverlink_robot.set_config(watchdog_ms=10)
    assert err.value.argument == "watchdog_ms" and "50..2000" in err.value.allowed
    with pytest.raises(CommandRangeError, match="one of watchdog_ms"):
        roverlink_robot.set_config(no_such_field=1)
    with pytest.raises(NackError) as nack:  # in range, inconsistent: the board refuses
        roverlink_robot.set_config(steering_min_cdeg=9500)
    assert nack.value.reason is enums.NackReason.INVALID_CONFIG
    assert nack.value.field in ("steering_min_cdeg", "steering_center_cdeg")  # the firmware's detail, by name
    assert nack.value.field in str(nack.value)


def test_save_config_is_refused_while_armed(roverlink_robot: Robot) -> None:
    roverlink_robot.arm()
    with pytest.raises(NackError, match="disarm first") as err:
        roverlink_robot.save_config()
    assert err.value.reason is enums.NackReason.ARMED
    roverlink_robot.disarm()
    roverlink_robot.save_config()


# -- failsafe and watchdog --------------------------------------------------------------------------------
def test_a_program_that_stops_commanding_stops_the_robot(roverlink_robot: Robot, roverlink_emulator: Any) -> None:
    failsafes: list[enums.FailsafeReason] = []
    roverlink_robot.on_failsafe(failsafes.append)
    roverlink_robot.arm()
    drive_for(roverlink_robot, 0.5, 0.3)
    last_call = roverlink_robot.now()
    while roverlink_emulator.truth.firmware.state is SessionState.ARMED:
        roverlink_robot.sleep(0.001)
    fw = roverlink_emulator.truth.firmware
    # failsafe within watchdog + one tick of the last valid host frame, and within
    # command_timeout + watchdog + one tick of the user's last command
    assert (fw.micros - fw.last_valid_frame_us) / 1e6 <= roverlink_robot.watchdog_s + TICK_S + 0.001
    assert (
        roverlink_robot.now() - last_call
        <= roverlink_robot.command_timeout_s + roverlink_robot.watchdog_s + TICK_S + 0.002
    )
    assert fw.failsafe_reason is enums.FailsafeReason.COMM_TIMEOUT
    roverlink_robot.sleep(0.1)
    assert roverlink_robot.failsafe is enums.FailsafeReason.COMM_TIMEOUT and failsafes
    with pytest.raises(FailsafeError, match="renew them in a loop"):
        roverlink_robot.drive(0.3, 0.0)
    roverlink_robot.arm()
    roverlink_robot.drive(0.3, 0.0)
    assert roverlink_robot.state == "armed"


def test_slow_but_steady_commands_keep_the_robot_driving(roverlink_robot: Robot, roverlink_emulator: Any) -> None:
    roverlink_robot.arm()
    for _ in range(10):  # 5 Hz: each command expires, but the next comes before the watchdog
        roverlink_robot.drive(0.2, 0.0)
        roverlink_robot.sleep(0.2)
    assert roverlink_emulator.truth.firmware.state is SessionState.ARMED


# -- resets --------------------------------------------------------------------------------------------------
def test_board_reset_is_detected_reported_and_the_session_reopened(
    roverlink_robot: Robot, roverlink_emulator: Any
) -> None:
    resets: list[SessionResetError] = []
    noticed: list[float] = []
    roverlink_robot.on_reset(lambda err: (resets.append(err), noticed.append(roverlink_robot.now())))
    roverlink_robot.arm()
    drive_for(roverlink_robot, 0.3, 0.2)
    old = roverlink_robot.identity.boot_id
    roverlink_emulator.reset_mcu()
    while roverlink_emulator.truth.mcu.phase != "running":
        roverlink_robot.sleep(0.001)
    booted = roverlink_robot.now()
    roverlink_robot.sleep(0.1)
    assert resets and resets[0].old_boot_id == old
    # within one feedback period of the new boot talking (its setup writes the EEPROM boot counter first)
    setup_s = 4 * 0.0034
    assert noticed[0] - booted <= setup_s + 1 / roverlink_robot.identity.feedback_hz
    with pytest.raises(SessionResetError) as err:
        roverlink_robot.drive(0.2, 0.0)
    assert err.value.old_boot_id == old
    with pytest.raises(NotArmedError):
        roverlink_robot.drive(0.2, 0.0)
    assert roverlink_robot.identity.boot_id != old and roverlink_robot.stats.reconnects == 1
    # nothing of the old session was applied in the new one
    fw = roverlink_emulator.truth.firmware
    assert fw.state is SessionState.DISARMED and fw.targets_mm_s == (0.0, 0.0)
    roverlink_robot.arm()
    drive_for(roverlink_robot, 0.2, 0.2)
    assert roverlink_emulator.truth.firmware.state is SessionState.ARMED


@pytest.mark.roverlink(auto_rearm=True)
def test_auto_rearm_re_arms_after_a_reset_but_never_replays_the_old_command(
    roverlink_robot: Robot, roverlink_emulator: Any
) -> None:
    roverlink_robot.arm()
    drive_for(roverlink_robot, 0.3, 0.2)
    roverlink_robot.drive(0.2, 0.0, hold_s=5.0)  # still live when the reset is noticed
    roverlink_emulator.brown_out(20.0)  # back in ~0.1 s
    roverlink_robot.sleep(2.0)  # no command from the user meanwhile
    fw = roverlink_emulator.truth.firmware
    assert fw.boot_id == roverlink_robot.identity.boot_id
    assert fw.targets_mm_s == (0.0, 0.0) and fw.ack_tick == 0  # no setpoint applied in the new boot
    drive_for(roverlink_robot, 0.2, 0.2)
    assert roverlink_emulator.truth.firmware.state is SessionState.ARMED


def test_connect_to_ready_after_a_dtr_reset_is_boot_time_plus_one_round_trip() -> None:
    """Measured on the virtual clock: no sleeps in the SDK, so ready follows the boot announcement
    by one round trip (HELLO + GET_CONFIG out, IDENTITY + CONFIG back: ~107 bytes at 115200 baud)."""
    robot = Robot.connect("emu://diffdrive-tb6612?clock=virtual&dtr=1")
    try:
        emu = robot.emulator
        boot_announced = next(f.time_us for f in emu.truth.faults if f.kind == "dtr_reset") / 1e6
        ready = robot.stats.connect_time_s
        assert ready is not None
        bootloader = emu.bootloader_ms / 1000
        bytes_round_trip = (15 + 6) + (49 + 47)  # HELLO + GET_CONFIG, IDENTITY + CONFIG (frame bytes, at most)
        one_round_trip = bytes_round_trip * 10 / 115200 + 2 * 0.001 + 0.002  # + adapter latency + host polling
        setup = 4 * 0.0034 + 40 * 10 / 115200  # the boot counter's EEPROM write, then the announcement itself
        assert boot_announced == 0.0
        assert bootloader < ready <= bootloader + setup + one_round_trip
    finally:
        robot.close()


# -- connecting to what is not a good board -------------------------------------------------------------
class ScriptedTransport(Transport):
    """A fake port: answers each write with `reply(data)` on a virtual clock."""

    virtual = True

    def __init__(self, reply: Any) -> None:
        self.url = "/dev/ttyFAKE"
        self.now = 0.0
        self.inbox = b""
        self.reply = reply

    def clock(self) -> float:
        return self.now

    def read(self, timeout_s: float) -> bytes:
        self.now += max(timeout_s, 0.0005)
        data, self.inbox = self.inbox, b""
        return data

    def write(self, data: bytes) -> None:
        self.inbox += self.reply(data)

    def close(self) -> None:
        pass


@pytest.mark.parametrize(
    ("reply", "expected"),
    [
        (lambda data: b"", "nothing at all was received: check the cable"),
        (lambda data: b"\x7f\x13garbage at the wrong baud\xff", "not one valid RoverLink frame: check the baud"),
    ],
)
def test_connect_timeout_says_what_was_heard(reply: Any, expected: str) -> None:
    with pytest.raises(ConnectTimeoutError) as err:
        Robot.connect(transport=ScriptedTransport(reply), timeout_s=0.5)
    assert isinstance(err.value, TimeoutError)
    assert "/dev/ttyFAKE" in str(err.value) and "115200 baud" in str(err.value) and expected in str(err.value)


def test_incompatible_firmware_is_refused_with_both_hashes_and_the_fix() -> None:
    decoder = FrameDecoder()

    def board(data: bytes) -> bytes:
        out = b""
        for ev in decoder.feed(data):
            if isinstance(ev, Frame) and isinstance(ev.message, messages.Hello):
                out += encode_frame(
                    messages.Identity(
                        PROTOCOL_VERSION,
                        0xCAFEF00D,
                        (0, 0, 9),
                        enums.Board.UNO,
                        enums.Capability.ACKERMANN,
                        7,
                        10,
                        enums.IdentityReason.HELLO_REJECTED,
                        ev.seq,
                        250,
                        enums.FeedbackMode.STREAM,
                        50,
                        "AckermannPiCar",
                    ),
                    0,
                )
        return out

    with pytest.raises(IncompatibleFirmwareError) as err:
        Robot.connect(transport=ScriptedTransport(board), timeout_s=1.0)
    text = str(err.value)
    assert "0xCAFEF00D" in text and "roverlink firmware flash --example AckermannPiCar --port /dev/ttyFAKE" in text


@pytest.mark.roverlink(profile="picar", mode="lockstep")
def test_lockstep_on_firmware_without_it_is_unsupported(roverlink_options: dict[str, Any]) -> None:
    with pytest.raises(UnsupportedError, match="LOCKSTEP"):
        Robot.connect("emu://picar?clock=virtual", mode="lockstep")


# -- threads and descriptors -----------------------------------------------------------------------------
@pytest.mark.roverlink(profile="diffdrive-bts7960", mode="lockstep")
def test_a_lockstep_robot_streams_while_not_armed_and_answers_each_command_while_armed(roverlink_robot: Robot) -> None:
    assert roverlink_robot.mode == "lockstep" and roverlink_robot.state == "disarmed"
    period = round(1 / (roverlink_robot.identity.feedback_hz * TICK_S))
    disarmed = [roverlink_robot.wait_feedback(timeout_s=0.2) for _ in range(10)]  # no command in flight
    assert {b.tick - a.tick for a, b in itertools.pairwise(disarmed)} == {period}
    assert not any(f.armed for f in disarmed)
    roverlink_robot.arm()
    answered = []
    for k in range(5):
        roverlink_robot.drive(0.05 * k, 0.0)
        answered.append(roverlink_robot.wait_feedback(timeout_s=0.2))  # the one answering this command
    assert all(f.armed for f in answered) and len({f.ack_seq for f in answered}) == 5
    roverlink_robot.sleep(roverlink_robot.watchdog_s + 0.05)  # no command: the watchdog fails the board safe
    failsafe = [roverlink_robot.wait_feedback(timeout_s=0.2) for _ in range(5)]
    assert roverlink_robot.state == "failsafe" and all(f.failsafe_reason for f in failsafe)
    assert {b.tick - a.tick for a, b in itertools.pairwise(failsafe)} == {period}


@pytest.mark.roverlink(profile="diffdrive-bts7960", mode="lockstep")
def test_a_silent_disarmed_lockstep_robot_is_a_silence_as_in_stream_mode(
    roverlink_robot: Robot, roverlink_emulator: Any
) -> None:
    roverlink_robot.wait_feedback()
    roverlink_emulator.cut_link("m2h")
    last = roverlink_robot.now()
    with pytest.raises(FeedbackTimeoutError, match="the link may be cut") as error:
        roverlink_robot.wait_feedback(timeout_s=0.5)
    assert error.value.lockstep
    assert roverlink_robot.now() - last == pytest.approx(2.0, abs=0.05)  # waited out as a reset's silence


@pytest.mark.roverlink(profile="diffdrive-bts7960", mode="lockstep")
def test_an_armed_lockstep_robot_cut_off_mid_command_is_told_the_link_may_be_cut(
    roverlink_robot: Robot, roverlink_emulator: Any
) -> None:
    """The command expires during the long wait (a silence waited out as a reset's); the hint is
    about the link, not "drive first", which is for a wait begun with no command live."""
    roverlink_robot.arm()
    roverlink_robot.drive(0.05, 0.0)
    roverlink_robot.wait_feedback(timeout_s=0.2)
    roverlink_emulator.cut_link("m2h")
    with pytest.raises(FeedbackTimeoutError, match="the link may be cut"):
        roverlink_robot.wait_feedback(timeout_s=0.2)


def _fds() -> int:
    return len(os.listdir("/proc/self/fd"))


def test_close_leaves_no_threads_or_descriptors_and_calls_are_thread_safe() -> None:
    threads, fds = set(threading.enumerate()), _fds()
    for _ in range(2):
        # speed=4: the board's 0.25 s watchdog would be 62 ms of wall time, which a loaded machine's
        # scheduling can miss with three threads driving; the watchdog is not what is tested here.
        with Robot.connect("emu://diffdrive-tb6612?speed=4", watchdog_s=1.0) as robot:
            robot.arm()
            errors: list[BaseException] = []

            def user(k: int, robot: Robot = robot, errors: list[BaseException] = errors) -> None:
                try:
                    end = time.monotonic() + 0.3
                    while time.monotonic() < end:
                        robot.drive(0.1 * k, 0.0)
                        robot.stats  # noqa: B018
                        robot.wait_feedback(1.0)
                except BaseException as exc:  # pragma: no cover - the assertion shows it
                    errors.append(exc)

            workers = [threading.Thread(target=user, args=(k,)) for k in (1, 2, 3)]
            for w in workers:
                w.start()
            for w in workers:
                w.join()
            assert not errors
            assert robot.feedback is not None and robot.feedback.armed
    assert set(threading.enumerate()) == threads
    assert _fds() == fds


def test_the_odometry_pose_says_when_the_board_sampled_it(roverlink_robot: Robot) -> None:
    """One pose type for the wheels' pose and a pose source's: the wheels' carries the host time
    of the FEEDBACK it was integrated from, which a pilot needs as much as the place."""
    roverlink_robot.arm()
    for _ in range(5):
        roverlink_robot.drive(0.2, 0.0)
        sample = roverlink_robot.wait_feedback()
    pose = roverlink_robot.odometry.pose
    latest = roverlink_robot.feedback
    assert latest is not None and pose.mcu_time_us == latest.mcu_time_us
    assert pose.time_s == latest.host_time_s and 0 < pose.time_s <= roverlink_robot.now()
    assert sample.pose is not None and sample.pose.time_s == sample.host_time_s
