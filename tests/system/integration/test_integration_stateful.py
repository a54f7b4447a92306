"""SDK + emulator under random interleavings of user calls, time and faults, checked against a model.

Rules: drive (good and bad input), arm, disarm, set_config, time passing, bit flips, drops,
insertions, a cut link, MCU reset, DTR reset, brown-out, and a "settle" that heals the link.
Invariants, after every step:

- no setpoint of an old session is ever applied after a reset: the firmware only has non-zero
  targets if the user gave a drive command that succeeded in this boot;
- the firmware is never ARMED longer than watchdog + one control tick after the last valid host
  frame, nor (user's view) longer than command_timeout + watchdog + one tick after the user's last
  call: a program that stops commanding stops the robot;
- a reliable config change is applied exactly once: the firmware holds the last value a call
  succeeded with (or, after a call that failed, that value or the attempted one), never an older one;
- after any pattern of feedback loss, once the link is healed, the SDK's cumulative counts equal
  the firmware's;
- only documented exceptions escape a call; close() leaves no threads or descriptors.
"""

from __future__ import annotations

import contextlib
import math
import os
import threading
from typing import Any

from hypothesis import settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, invariant, rule

from emulator.firmware.statemachine import SessionState
from host_sdk import Robot
from host_sdk.errors import (
    CommandRangeError,
    FeedbackTimeoutError,
    NackError,
    NotArmedError,
    RequestTimeoutError,
    SessionResetError,
)
from host_sdk.profiles import PROFILES

PROFILE_NAME = os.environ.get("HYPOTHESIS_PROFILE", "ci")  # the profiles are registered in tests/conftest.py

TICK_US = 10_000
MODES = {"diffdrive-tb6612": "stream", "diffdrive-bts7960": "lockstep", "picar": "stream"}
REQUEST_ERRORS = (RequestTimeoutError, SessionResetError, NackError)
DRIVE_ERRORS = (NotArmedError, SessionResetError, NackError, RequestTimeoutError)  # the last: auto_rearm arms


class SdkAgainstEmulator(RuleBasedStateMachine):
    robot: Robot
    emu: Any

    @initialize(
        profile=st.sampled_from(sorted(MODES)),
        seed=st.integers(0, 2**16),
        auto_rearm=st.booleans(),
    )
    def connect(self, profile: str, seed: int, auto_rearm: bool) -> None:
        self.threads = set(threading.enumerate())
        self.fds = len(os.listdir("/proc/self/fd"))
        self.profile = profile
        self.auto_rearm = auto_rearm
        self.robot = Robot.connect(
            f"emu://{profile}?clock=virtual&seed={seed}",
            mode=MODES[profile],
            auto_rearm=auto_rearm,  # type: ignore[arg-type]
        )
        self.emu = self.robot.emulator
        self.ackermann = PROFILES[profile].kinematics == "ackermann"
        self.default_accel = PROFILES[profile].config.accel_limit_mm_s2
        self.accel_ok = {self.default_accel}
        self.next_accel = 500
        self.drive_boot: int | None = None
        self.hold_until_s = 0.0
        self.last_user_s = self.robot.now()
        self.last_reset_s = -10.0
        self.wheels = 1 if self.ackermann else 2

    def teardown(self) -> None:
        robot = getattr(self, "robot", None)
        if robot is None:
            return
        robot.close()
        robot.close()
        assert set(threading.enumerate()) == self.threads
        assert len(os.listdir("/proc/self/fd")) == self.fds

    def _user(self) -> None:
        self.last_user_s = self.robot.now()

    def _reset_happened(self) -> None:
        self.accel_ok = {self.default_accel}  # the board reloads its saved configuration
        self.last_reset_s = self.robot.now()

    # -- user calls -------------------------------------------------------------------------------
    @rule(
        v=st.floats(-0.3, 0.3),
        w=st.floats(-1.0, 1.0),
        repeat=st.integers(1, 15),
        hold_s=st.sampled_from([None, None, 1.0, 3.0]),
    )
    def drive(self, v: float, w: float, repeat: int, hold_s: float | None) -> None:
        for _ in range(repeat):
            try:
                if self.ackermann:
                    self.robot.drive_ackermann(v, max(-0.4, min(0.4, w)), hold_s=hold_s)
                else:
                    self.robot.drive(v, w, hold_s=hold_s)
                self.drive_boot = self.robot.identity.boot_id
                if hold_s is not None:
                    self.hold_until_s = max(self.hold_until_s, self.robot.now() + hold_s)
            except DRIVE_ERRORS:
                pass
            self._user()
            self.robot.sleep(0.02)

    @rule(bad=st.sampled_from([math.nan, math.inf, -math.inf, 25.0, -40.0]))
    def bad_drive(self, bad: float) -> None:
        for call in (lambda: self.robot.drive(bad, 0.0), lambda: self.robot.drive(0.0, bad * 10)):
            try:
                call()
            except CommandRangeError:
                continue
            raise AssertionError(f"bad input {bad} was accepted")

    @rule()
    def arm(self) -> None:
        with contextlib.suppress(*REQUEST_ERRORS):
            self.robot.arm(wait_esc=False)
        self._user()

    @rule()
    def disarm(self) -> None:
        with contextlib.suppress(*REQUEST_ERRORS):
            self.robot.disarm()
        self._user()

    @rule()
    def set_config(self) -> None:
        value = self.next_accel
        self.next_accel += 7
        try:
            self.robot.set_config(accel_limit_mm_s2=value)
        except REQUEST_ERRORS:
            self.accel_ok = self.accel_ok | {value}  # maybe applied (its ACK lost), never twice
        else:
            self.accel_ok = {value}
        self._user()

    @rule(seconds=st.floats(0.01, 0.6))
    def time_passes(self, seconds: float) -> None:
        self.robot.sleep(seconds)

    # -- faults -------------------------------------------------------------------------------------
    @rule(
        kind=st.sampled_from(["bitflip", "drop", "insert"]),
        rate=st.sampled_from([1e-4, 5e-4, 2e-3]),
        direction=st.sampled_from(["h2m", "m2h", "both"]),
    )
    def line_noise(self, kind: str, rate: float, direction: str) -> None:
        if kind == "bitflip":
            rate /= 8  # per bit
        getattr(self.emu, f"set_{kind}_rate")(rate, direction)

    @rule(seconds=st.floats(0.05, 1.0))
    def cut_link(self, seconds: float) -> None:
        self.emu.cut_link()
        self.robot.sleep(seconds)
        self.emu.restore_link()

    @rule(kind=st.sampled_from(["reset_mcu", "dtr_reset", "brown_out"]))
    def reset(self, kind: str) -> None:
        if kind == "brown_out":
            self.emu.brown_out(20.0)  # a quick reboot: a live command may still be held when it is noticed
        else:
            getattr(self.emu, kind)()
        self._reset_happened()

    @rule()
    def settle(self) -> None:
        """Heal the link and bring the robot to rest: then the SDK's counts equal the firmware's."""
        for kind in ("bitflip", "drop", "insert"):
            getattr(self.emu, f"set_{kind}_rate")(0.0, "both")
        self.emu.restore_link()
        self.robot.sleep(0.05)
        for _ in range(60):  # at most ~6 s (a reset's bootloader plus handshake)
            if self.robot.state in ("disarmed", "armed", "failsafe"):
                break
            self.robot.sleep(0.1)
        try:
            self.robot.arm(wait_esc=False)
            for _ in range(60):
                self.robot.stop()
                self.robot.wait_feedback(0.5)
        except (*REQUEST_ERRORS, FeedbackTimeoutError, NotArmedError):
            return  # a reset crossed the settling: nothing to compare this time
        finally:
            self._user()
        fw = self.emu.truth.firmware
        sample = self.robot.feedback
        assert fw is not None and sample is not None
        assert sample.boot_id == fw.boot_id
        assert sample.encoder_counts[: self.wheels] == tuple(fw.encoder_counts[: self.wheels])

    # -- invariants -----------------------------------------------------------------------------------
    @invariant()
    def no_setpoint_of_an_old_session_is_applied(self) -> None:
        fw = self.emu.truth.firmware
        if fw is not None and any(t != 0 for t in fw.targets_mm_s):
            assert self.drive_boot == fw.boot_id, "a setpoint from another boot is applied"

    @invariant()
    def failsafe_follows_the_last_frame_and_the_last_user_call(self) -> None:
        fw = self.emu.truth.firmware
        if fw is None or fw.state is not SessionState.ARMED:
            return
        watchdog_us = fw.watchdog_ms * 1000
        assert (fw.micros - fw.last_valid_frame_us) % 2**32 <= watchdog_us + TICK_US
        quiet_s = self.robot.now() - max(self.last_user_s, self.hold_until_s)
        bound = self.robot.command_timeout_s + fw.watchdog_ms / 1000 + TICK_US / 1e6 + 0.005
        auto_rearmed = self.auto_rearm and self.robot.now() - self.last_reset_s < 8.0
        assert quiet_s <= bound or auto_rearmed, f"armed {quiet_s:.3f} s after the user's last call"

    @invariant()
    def config_changes_are_applied_exactly_once(self) -> None:
        fw = self.emu.truth.firmware
        if fw is not None:
            assert fw.config.accel_limit_mm_s2 in self.accel_ok


SdkAgainstEmulator.TestCase.settings = settings(
    max_examples=12 if PROFILE_NAME == "ci" else settings.default.max_examples,
    stateful_step_count=20 if PROFILE_NAME == "ci" else 50,
    deadline=None,
)
TestSdkAgainstEmulator = SdkAgainstEmulator.TestCase
