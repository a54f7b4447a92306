"""`Robot`: the object robot code holds. Connects, arms, drives, reads feedback and odometry.

    >>> from host_sdk import Robot
    >>> url = "emu://diffdrive-tb6612?clock=virtual"  # a board: "/dev/ttyACM0"
    >>> with Robot.connect(url, profile="diffdrive-tb6612") as robot:
    ...     robot.arm()
    ...     while robot.odometry.pose.x_m < 1.0:
    ...         robot.drive(0.3, 0.0)  # m/s, rad/s; renew it at least every command_timeout_s
    ...         sample = robot.wait_feedback()
    ...     robot.stop()
    ...     print(f"{robot.odometry.pose.x_m:.2f} m")
    1.00 m

Layering: a Transport (bytes) under the sans-I/O Session (host_sdk.session), run by a Runner
(host_sdk.robot.runner: one I/O thread on real ports and `emu://` on the wall clock, or inline on
the emulator's virtual clock), all three held by one `Link`. `Robot` connects, arms and closes;
its parts own the rest, each with its own state: `Driving` (drive calls, checked and turned into
setpoints by host_sdk.limits), `Feedback` (waits and callbacks), `Settings` (CONFIG, PID, lights)
and `OdometryView` (`robot.odometry`). Their methods are Robot's (`robot.drive` is
`Driving.drive`), so the API is flat. Every argument is checked by host_sdk.checks.

Threading (docs/sdk.md): every public method may be called from any thread; callbacks run on the
I/O thread without the lock held, and must not block for long nor wait for the board.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Literal, cast

from host_sdk import checks
from host_sdk.errors import RequestTimeoutError, RoverLinkError, UnsupportedError
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.robot.driving import Driving
from host_sdk.robot.feedback import Feedback
from host_sdk.robot.file_check import Mismatch, RobotFileCheck, chosen_kinematics, prepare
from host_sdk.robot.forward import part_method
from host_sdk.robot.link import Link
from host_sdk.robot.odometry import OdometryView
from host_sdk.robot.options import check_connect
from host_sdk.robot.settings import Settings
from host_sdk.robot_description import RobotDescription
from host_sdk.session import FeedbackSample, LinkState, LinkStatistics, RobotConfig, RobotIdentity, SessionOptions
from host_sdk.transport import Transport, open_transport
from protocol.generated.constants import FEEDBACK_HZ_DEFAULT, WATCHDOG_DEFAULT_MS
from protocol.generated.enums import Capability, FailsafeReason, FeedbackMode
from protocol.generated.messages import Arm, Disarm

if TYPE_CHECKING:
    from host_sdk.emulated import EmulatorHandle

log = logging.getLogger("host_sdk")


class Robot:
    """A connected RoverLink robot. Make one with `Robot.connect(url, ...)`; see the module docstring."""

    # == the parts' calls ==========================================================================
    drive = part_method("_driving", Driving.drive)
    set_wheel_speeds = part_method("_driving", Driving.set_wheel_speeds)
    drive_ackermann = part_method("_driving", Driving.drive_ackermann)
    stop = part_method("_driving", Driving.stop)
    wait_feedback = part_method("_feedback", Feedback.wait_feedback)
    feedback_stream = part_method("_feedback", Feedback.feedback_stream)
    on_feedback = part_method("_feedback", Feedback.on_feedback)
    on_reset = part_method("_feedback", Feedback.on_reset)
    on_odometry_gap = part_method("_feedback", Feedback.on_odometry_gap)
    on_failsafe = part_method("_feedback", Feedback.on_failsafe)
    on_log = part_method("_feedback", Feedback.on_log)
    read_config = part_method("_settings", Settings.read_config)
    set_config = part_method("_settings", Settings.set_config)
    pid = part_method("_settings", Settings.pid)
    set_pid = part_method("_settings", Settings.set_pid)
    save_config = part_method("_settings", Settings.save_config)
    set_lights = part_method("_settings", Settings.set_lights)
    lights = part_method("_settings", Settings.lights)
    board_link_stats = part_method("_settings", Settings.board_link_stats)

    # == connecting ===============================================================================
    @classmethod
    def connect(
        cls,
        url: str = "emu://",
        *,
        profile: str | None = None,
        kinematics: DiffDrive | Ackermann | None = None,
        robot: str | Path | RobotDescription | None = None,
        allow_mismatch: bool = False,
        baud: int = 115200,
        watchdog_s: float = WATCHDOG_DEFAULT_MS / 1000,
        mode: Literal["stream", "lockstep"] = "stream",
        feedback_hz: int = FEEDBACK_HZ_DEFAULT,
        timeout_s: float = 5.0,
        clamp: bool = False,
        auto_rearm: bool = False,
        paced: bool = False,
        command_timeout_s: float | None = None,
        request_timeout_s: float = 0.25,
        request_tries: int = 5,
        transport: Transport | None = None,
    ) -> Robot:
        """Open `url`, handshake, read the configuration; returns a ready (disarmed) robot.

        url: a serial device (/dev/ttyACM0, COM3), any pyserial URL (socket://host:port, loop://,
            spy:///dev/ttyUSB0), or an in-process emulator emu://PROFILE?seed=N&faults=...&clock=real|virtual.
        profile: reference robot name (host_sdk.profiles.PROFILES) for the kinematics; by default the
            firmware's example name (or the emu:// profile, or the emu://?robot=PATH file) picks it.
            kinematics: your own DiffDrive/Ackermann.
        robot: your robot file (or its RobotDescription): kinematics from it, the board compared with it
            (RobotMismatchError; allow_mismatch=True: a warning, in `mismatches`), its limits and gains set.
        watchdog_s: firmware watchdog requested in HELLO, within the firmware's range (WATCHDOG_MIN_MS..MAX_MS).
        mode: "stream" (FEEDBACK at feedback_hz) or "lockstep" (one FEEDBACK per setpoint while
            armed; at feedback_hz while not armed).
        clamp: scale/clamp commands beyond the limits instead of raising CommandRangeError.
        auto_rearm: after a board reset (or a watchdog failsafe), re-arm by itself instead of
            raising on the next command (an opt-in, logged as a warning at connect).
        paced: lockstep only: the I/O thread sends the live setpoint once per feedback period on the
            board's tick grid, so FEEDBACK comes at feedback_hz however late your thread runs; drive()
            then replaces the live setpoint, sent at the next slot (at most a period later).
        command_timeout_s: how long one drive command stays live (default watchdog_s / 2).
        Raises ArgumentError (CommandRangeError, ArgumentTypeError) naming a bad argument, and
        ConnectTimeoutError, IncompatibleFirmwareError, TransportError, UnsupportedError.
        """
        given = {k: v for k, v in locals().items() if k not in ("cls", "transport")}  # first: the arguments only
        file_args = ("robot", "allow_mismatch")  # prepare() checks those
        options = check_connect(transport=transport, **{k: v for k, v in given.items() if k not in file_args})
        check = prepare(robot, profile, kinematics, allow_mismatch)
        # By URL, it can be opened again the same way (reopen): these arguments, but the transport.
        again = None if transport is not None else functools.partial(cls.connect, **given)
        kinematics = check.description.kinematics() if check is not None else kinematics
        if transport is None:
            transport = open_transport(url, baud)
        options = dataclasses.replace(options, url=transport.url)
        made = cls(transport, options, profile=profile, kinematics=kinematics, clamp=clamp)
        made._file_check = check
        made._again = again
        try:
            made._open(timeout_s)
            if check is not None:
                check.compare_lights(made, made.url)
                check.apply(made)
        except BaseException:
            made._shutdown(disarm=False)
            raise
        if options.auto_rearm:  # an opt-in that drives again by itself: said once, at the start
            log.warning(
                "%s: auto_rearm is on: the robot re-arms by itself after a board reset or a watchdog failsafe", made.url
            )
        return made

    def reopen(self) -> Robot:
        """A new Robot connected the way this one was (its URL, every option of `connect`): for a
        port that was lost and is back (a USB adapter plugged in again). This one is left as it is
        (close it). Raises UnsupportedError for a robot connected over a `transport=` it was given
        (there is nothing to open again), else what `connect` raises."""
        if self._again is None:
            raise UnsupportedError(
                f"{self.url} was connected over a transport given to connect(): it cannot be "
                "opened again; connect it again yourself"
            )
        return self._again()

    @property
    def can_reopen(self) -> bool:
        """`reopen()` can connect again: the robot was connected by URL, not over a given transport."""
        return self._again is not None

    def __init__(
        self,
        transport: Transport,
        options: SessionOptions,
        *,
        profile: str | None = None,
        kinematics: DiffDrive | Ackermann | None = None,
        clamp: bool = False,
    ) -> None:
        """Use `Robot.connect`; this only wires the pieces (nothing is sent)."""
        self._link = link = Link(transport, options)
        self._profile_name = profile
        self._user_kinematics = kinematics
        self._driving = Driving(link, self.arm, clamp)
        self._feedback = Feedback(link)
        self._settings = Settings(link, self._configured)
        self.odometry = OdometryView(link)
        """Pose and body velocities from the wheel encoders; `odometry.reset()` sets the origin."""
        self._file_check: RobotFileCheck | None = None
        self._again: Callable[[], Robot] | None = None

    def _open(self, timeout_s: float) -> None:
        runner, s = self._link.runner, self._link.session
        runner.start()
        runner.wait(lambda: s.ready or runner.broken(), timeout_s)
        with self._link.lock:
            runner.check()
            if not s.ready:
                raise s.connect_timeout_error(timeout_s)
            identity = s.identity
            assert identity is not None
            if (
                self._link.options.feedback_mode is FeedbackMode.LOCKSTEP
                and identity.feedback_mode is not FeedbackMode.LOCKSTEP
            ):
                raise UnsupportedError(
                    f"mode='lockstep' was asked for, but {identity.robot_name or 'the firmware'} on {self.url} has no "
                    "LOCKSTEP capability: connect with mode='stream'",
                    Capability.LOCKSTEP,
                )
            if self._file_check is not None:  # before the kinematics: their check names less
                self._file_check.compare(identity, s.config, self.url)
            s.set_kinematics(self._resolve_kinematics())

    def _resolve_kinematics(self) -> DiffDrive | Ackermann | None:
        s = self._link.session
        assert s.identity is not None and s.config is not None
        caps = s.identity.capabilities
        kin = chosen_kinematics(self._user_kinematics, self._profile_name, self._link.transport, s.identity, s.config)
        if isinstance(kin, DiffDrive) and not caps & Capability.DIFF_DRIVE:
            raise UnsupportedError(
                f"differential-drive kinematics, but the firmware on {self.url} cannot drive two wheels",
                Capability.DIFF_DRIVE,
            )
        if isinstance(kin, Ackermann) and not caps & Capability.ACKERMANN:
            raise UnsupportedError(
                f"Ackermann kinematics, but the firmware on {self.url} has no steering", Capability.ACKERMANN
            )
        return kin

    def _configured(self) -> None:
        """After a configuration change: kinematics taken from the board's config follow it."""
        with self._link.lock:
            if self._user_kinematics is None and self._link.session.kinematics is not None:
                self._link.session.set_kinematics(self._resolve_kinematics())

    def _next_feedback(self, timeout: float, report_reset: bool) -> FeedbackSample:
        """host_sdk.aio's wait: `wait_feedback` with the choice of reporting a reset."""
        return self._feedback.next(timeout, report_reset)

    # == properties ================================================================================
    @property
    def url(self) -> str:
        return self._link.transport.url

    @property
    def transport(self) -> Transport:
        return self._link.transport

    @property
    def emulator(self) -> EmulatorHandle | None:
        """The in-process emulator behind an emu:// URL (the transport's `device`; None otherwise),
        typed as what a program may use of it (host_sdk.emulated: truth, time, faults).

        On the virtual clock use it freely; on the real clock an I/O thread drives it, so wrap
        access in `with robot.transport.locked() as emu:`."""
        # The emu:// plugin's device is an emulator.Emulator, which host_sdk must not import.
        return cast("EmulatorHandle | None", self._link.transport.device)

    @property
    def virtual_clock(self) -> bool:
        """True on an emulator's virtual clock: time moves only while the robot waits or sleeps."""
        return self._link.transport.virtual

    @property
    def closed(self) -> bool:
        return self._link.runner.closed

    @property
    def clamp(self) -> bool:
        """The default of every drive call's `clamp` (set in connect)."""
        return self._driving.clamp

    @clamp.setter
    def clamp(self, value: bool) -> None:
        self._driving.clamp = checks.flag("clamp", value)

    @property
    def identity(self) -> RobotIdentity:
        """Firmware version, board, spec hash, capabilities and boot_id of the current session."""
        return self._link.identity()

    @property
    def config(self) -> RobotConfig:
        """The board's configuration as last read or written (see `read_config()` for a fresh copy)."""
        return self._link.config()

    @property
    def mismatches(self) -> tuple[Mismatch, ...]:
        """How the board differs from the robot file connected with allow_mismatch=True (else empty)."""
        return self._file_check.mismatches if self._file_check is not None else ()

    @property
    def gains_notice(self) -> str | None:
        """The line saying how the robot file's [pid] changed the board's gains at connect (None:
        the board already had them, or no file)."""
        return self._file_check.gains_notice if self._file_check is not None else None

    @property
    def description(self) -> RobotDescription | None:
        """The robot file connect(robot=) checked the board against (None: connected without one)."""
        return self._file_check.description if self._file_check is not None else None

    @property
    def kinematics(self) -> DiffDrive | Ackermann | None:
        with self._link.lock:
            return self._link.session.kinematics

    @property
    def armed(self) -> bool:
        """The host's belief: ARM acknowledged and no failsafe, reset, DISARM or broken link since."""
        with self._link.lock:
            return self._link.session.armed

    @property
    def failsafe(self) -> FailsafeReason | None:
        """The latched FAILSAFE reason (None when not in failsafe)."""
        with self._link.lock:
            return self._link.session.failsafe

    @property
    def state(self) -> str:
        """ "connecting", "disarmed", "armed", "failsafe", "incompatible", "broken" (the link failed:
        the port vanished, or the runner stopped; every call raises why) or "closed"."""
        with self._link.lock:
            s = self._link.session
            if self._link.runner.closed:
                return "closed"
            if s.state is not LinkState.OPEN:
                return str(s.state.value)
            if s.failsafe is not None:
                return "failsafe"
            return "armed" if s.armed else "disarmed"

    @property
    def feedback(self) -> FeedbackSample | None:
        """The latest FEEDBACK (None before the first)."""
        with self._link.lock:
            return self._link.session.latest

    @property
    def feedback_age_s(self) -> float | None:
        """Seconds since the last FEEDBACK arrived (None before the first): a board in its bootloader,
        a cut cable or an armed lockstep robot with no command in flight all go quiet (a lockstep
        robot that is not armed streams at feedback_hz, as in stream mode)."""
        with self._link.lock:
            last = self._link.session.last_feedback_s
            return None if last is None else self._link.transport.clock() - last

    @property
    def stats(self) -> LinkStatistics:
        """Link statistics of the host side (frames, errors, retries, NACKs, RTT, clock sync, resets)."""
        with self._link.lock:
            return self._link.session.stats(self._link.transport.clock())

    @property
    def watchdog_s(self) -> float:
        """Watchdog period the board granted."""
        with self._link.lock:
            return self._link.session.watchdog_s

    @property
    def command_timeout_s(self) -> float:
        return self._link.options.command_timeout

    @property
    def mode(self) -> str:
        with self._link.lock:
            return "lockstep" if self._link.session.feedback_mode is FeedbackMode.LOCKSTEP else "stream"

    def now(self) -> float:
        """The session's clock in seconds (the host's monotonic clock, or the emulator's virtual time)."""
        return self._link.transport.clock()

    def mcu_to_host_s(self, mcu_time_us: int) -> float:
        """Host time of an (unwrapped) MCU timestamp, from PING/PONG time sync."""
        us = checks.number("mcu_time_us", mcu_time_us, 0, 1e18, unit="us")
        with self._link.lock:
            return self._link.session.mcu_to_host_s(us)

    # == arming ====================================================================================
    def arm(self, timeout_s: float = 2.0, *, wait_esc: bool = True) -> None:
        """Enable the motors (ARM with this session's boot_id); clears a latched FAILSAFE.

        A reset not yet reported is raised first (SessionResetError, once: arm again). On a robot
        with an ESC still in its power-up arming window, waits for the window to end first
        (wait_esc=False: don't; the board then holds neutral until it ends). `timeout_s` bounds the
        wait for a session that is re-opening after a reset. Raises NackError, RequestTimeoutError, SessionResetError.
        """
        timeout = checks.seconds("timeout_s", timeout_s)
        checks.flag("wait_esc", wait_esc)
        runner, s = self._link.runner, self._link.session
        with self._link.lock:
            runner.check()
            error = s.take_reset()
            if error is not None:
                raise error
        if not runner.wait(lambda: s.ready or runner.broken(), timeout):
            runner.check()
            raise RequestTimeoutError("ARM", 0, timeout)
        runner.check()
        if wait_esc:
            left = s.esc_window_left(self._link.transport.clock())
            if left > 0:
                self.sleep(left)
        with self._link.lock:
            identity = s.identity
            assert identity is not None
            msg = Arm(boot_id=identity.boot_id)
        self._link.request(msg)

    def disarm(self) -> None:
        """Disable the motors (the configured safe state). Also clears a latched FAILSAFE."""
        with self._link.lock:
            self._link.runner.check()
            self._link.session.release()
        self._link.runner.request(Disarm(), report_reset=False)  # cleanup: a reset is left to other calls

    def sleep(self, seconds: float) -> None:
        """Wait `seconds` on the session's clock: wall time, or virtual time with an emu://...?clock=virtual
        robot, where this is what moves the emulator forward (so the same robot code runs in tests)."""
        duration = checks.seconds("seconds", seconds, zero=True)
        with self._link.lock:
            self._link.check_open()
        self._link.runner.wait(lambda: self._link.runner.closed, duration)

    # == closing ===================================================================================
    def close(self) -> None:
        """Disarm (best effort), stop the I/O thread and release the port. Idempotent."""
        self._shutdown(disarm=True)

    def _shutdown(self, disarm: bool) -> None:
        runner, s = self._link.runner, self._link.session
        with self._link.lock:
            if runner.closed:
                return
            req = None
            if disarm and s.state is LinkState.OPEN and (s.armed or s.setpoint_live):
                s.release()
                req = s.submit(Disarm(), self._link.transport.clock(), tries=2, timeout_s=0.1)
                try:
                    runner.flush()
                except RoverLinkError:
                    req = None
        if req is not None:
            runner.wait(lambda: req.done or runner.broken(), 0.3)
        runner.stop()

    def __enter__(self) -> Robot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        # A robot dropped without close(): stop the I/O thread, which then releases the port.
        link = getattr(self, "_link", None)
        runner = link.runner if link is not None else None
        if runner is not None and not runner.closed:
            runner.abandon()

    def __repr__(self) -> str:
        return f"<Robot {self.url} {self.state}>"


__all__ = ["Robot"]
