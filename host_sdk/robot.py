"""`Robot`: the object robot code holds. Connects, arms, drives, reads feedback and odometry.

    from host_sdk import Robot

    with Robot.connect("/dev/ttyACM0", profile="diffdrive-tb6612") as robot:
        robot.arm()
        while robot.odometry.pose.x_m < 1.0:
            robot.drive(0.3, 0.0)              # m/s, rad/s; renew it at least every command_timeout_s
            robot.wait_feedback()
        robot.stop()

Layering: a Transport (bytes) under the sans-I/O Session (host_sdk.session) under this class,
which runs the session either on one I/O thread (real ports, and `emu://` on the wall clock) or
inline on the emulator's virtual clock (`emu://...?clock=virtual`: no threads; waiting, e.g.
`wait_feedback()` or `sleep()`, is what moves time). The session logic is the same in both.

Threading: every public method may be called from any thread. One lock guards the session; calls
that wait (connect, arm, requests, wait_feedback) wait on a condition variable without holding it.
Callbacks run on the I/O thread (inline: on the thread that is waiting) without the lock held;
they must not block for long.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any, Literal, TypeVar

from host_sdk.errors import (
    CommandRangeError,
    ConnectTimeoutError,
    EncodeError,
    FailsafeError,
    FeedbackTimeoutError,
    NotArmedError,
    RequestTimeoutError,
    RobotClosedError,
    RoverLinkError,
    SessionResetError,
    TransportError,
    UnsupportedError,
)
from host_sdk.kinematics import Ackermann, DiffDrive, KinematicsError
from host_sdk.odometry import Odometry as _Odometry
from host_sdk.odometry import Pose
from host_sdk.profiles import get_profile, kinematics_for, profile_for_example, steering_limits
from host_sdk.session import (
    Event,
    Failed,
    FailsafeEntered,
    FeedbackReceived,
    FeedbackSample,
    LinkState,
    LinkStatistics,
    LogReceived,
    PidGains,
    Request,
    ResetDetected,
    RobotConfig,
    RobotIdentity,
    Session,
    SessionOptions,
)
from host_sdk.transport import Transport, open_transport
from protocol.codec.message import Message
from protocol.generated.constants import PID_ALL_WHEELS, WHEEL_COUNT
from protocol.generated.enums import Capability, FailsafeReason, FeedbackMode, LogLevel
from protocol.generated.messages import (
    Arm,
    Config,
    Disarm,
    GetConfig,
    GetLinkStats,
    GetPid,
    LinkStats,
    Pid,
    SaveConfig,
    SetAckermann,
    SetConfig,
    SetPid,
    SetWheelSpeeds,
)

log = logging.getLogger("host_sdk")

T = TypeVar("T")
_IO_POLL_S = 0.02
_VIRTUAL_STEP_S = 0.001

FeedbackCallback = Callable[[FeedbackSample], None]
ResetCallback = Callable[[SessionResetError], None]
FailsafeCallback = Callable[[FailsafeReason], None]
LogCallback = Callable[[LogLevel, str], None]


def _finite(name: str, value: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise CommandRangeError(name, value, "a finite number")
    if not math.isfinite(value):
        raise CommandRangeError(name, value, "a finite number (not NaN or infinity)")
    return float(value)


class OdometryView:
    """The robot's odometry: pose and body velocity from cumulative encoder counts (thread-safe view)."""

    def __init__(self, robot: Robot) -> None:
        self._robot = robot

    @property
    def pose(self) -> Pose:
        """x, y (m), theta (rad, unwrapped), linear and angular velocity, MCU time of the last sample."""
        with self._robot._lock:
            return self._odometry().pose

    def reset(self, x_m: float = 0.0, y_m: float = 0.0, theta_rad: float = 0.0) -> None:
        """Set the pose (default: the origin); counting goes on from the next sample."""
        for name, value in (("x_m", x_m), ("y_m", y_m), ("theta_rad", theta_rad)):
            _finite(name, value)
        with self._robot._lock:
            self._odometry().reset(x_m, y_m, theta_rad)

    def _odometry(self) -> _Odometry:
        odo = self._robot._session.odometry
        if odo is None:
            raise UnsupportedError(
                "odometry needs the robot's kinematics: pass profile=... or kinematics=... to Robot.connect"
            )
        return odo

    def __repr__(self) -> str:
        try:
            p = self.pose
        except RoverLinkError:
            return "<Odometry unavailable>"
        return f"<Odometry x={p.x_m:.3f} m y={p.y_m:.3f} m theta={math.degrees(p.theta_rad):.1f} deg>"


class Robot:
    """A connected RoverLink robot. Make one with `Robot.connect(url, ...)`; see the module docstring."""

    # == connecting ===============================================================================
    @classmethod
    def connect(
        cls,
        url: str = "emu://",
        *,
        profile: str | None = None,
        kinematics: DiffDrive | Ackermann | None = None,
        baud: int = 115200,
        watchdog_s: float = 0.25,
        mode: Literal["stream", "lockstep"] = "stream",
        feedback_hz: int = 50,
        timeout_s: float = 5.0,
        clamp: bool = False,
        auto_rearm: bool = False,
        command_timeout_s: float | None = None,
        request_timeout_s: float = 0.25,
        request_tries: int = 5,
        transport: Transport | None = None,
    ) -> Robot:
        """Open `url`, handshake, read the configuration; returns a ready (disarmed) robot.

        url: a serial device (/dev/ttyACM0, COM3), any pyserial URL (socket://host:port, loop://,
            spy:///dev/ttyUSB0), or an in-process emulator emu://PROFILE?seed=N&faults=...&clock=real|virtual.
        profile: reference robot name (host_sdk.profiles.PROFILES) for the kinematics; by default the
            firmware's example name (or the emu:// profile) picks it. kinematics: your own DiffDrive/Ackermann.
        watchdog_s: firmware watchdog requested in HELLO (the board clamps it to 0.05..2 s).
        mode: "stream" (FEEDBACK at feedback_hz) or "lockstep" (one FEEDBACK per setpoint).
        clamp: scale/clamp commands beyond the limits instead of raising CommandRangeError.
        auto_rearm: after a board reset (or a watchdog failsafe), re-arm by itself instead of
            raising on the next command.
        command_timeout_s: how long one drive command stays live (default watchdog_s / 2).
        Raises ConnectTimeoutError, IncompatibleFirmwareError, TransportError, CommandRangeError.
        """
        _finite("watchdog_s", watchdog_s)
        if not 0.05 <= watchdog_s <= 2.0:
            raise CommandRangeError("watchdog_s", watchdog_s, "0.05..2.0 s (the firmware's watchdog range)")
        if mode not in ("stream", "lockstep"):
            raise CommandRangeError("mode", mode, "'stream' or 'lockstep'")
        if not (isinstance(feedback_hz, int) and 0 <= feedback_hz <= 100):
            raise CommandRangeError("feedback_hz", feedback_hz, "an integer in 0..100 Hz (0: the board's default)")
        _finite("timeout_s", timeout_s)
        if timeout_s <= 0:
            raise CommandRangeError("timeout_s", timeout_s, "a number of seconds > 0")
        if command_timeout_s is not None and not (_finite("command_timeout_s", command_timeout_s) > 0):
            raise CommandRangeError("command_timeout_s", command_timeout_s, "a number of seconds > 0")
        if profile is not None:
            get_profile(profile)
        if transport is None:
            transport = open_transport(url, baud)
        options = SessionOptions(
            watchdog_s=watchdog_s,
            feedback_mode=FeedbackMode.LOCKSTEP if mode == "lockstep" else FeedbackMode.STREAM,
            feedback_hz=feedback_hz,
            request_timeout_s=request_timeout_s,
            request_tries=request_tries,
            command_timeout_s=command_timeout_s,
            auto_rearm=auto_rearm,
            url=transport.url,
            baud=baud,
        )
        robot = cls(transport, options, profile=profile, kinematics=kinematics, clamp=clamp)
        try:
            robot._open(timeout_s)
        except BaseException:
            robot._shutdown(disarm=False)
            raise
        return robot

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
        self._transport = transport
        self._options = options
        self._session = Session(options)
        self._lock = threading.RLock()
        self._cond = threading.Condition(self._lock)
        self._virtual = transport.virtual
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self._closed = False
        self._io_error: TransportError | None = None
        self._profile_name = profile
        self._user_kinematics = kinematics
        self.clamp = clamp
        self._last_command_seq: int | None = None
        self._pending_callbacks: list[Event] = []
        self._on_feedback: list[FeedbackCallback] = []
        self._on_reset: list[ResetCallback] = []
        self._on_failsafe: list[FailsafeCallback] = []
        self._on_log: list[LogCallback] = []
        self.odometry = OdometryView(self)
        """Pose and body velocities from the wheel encoders; `odometry.reset()` sets the origin."""

    def _open(self, timeout_s: float) -> None:
        with self._lock:
            self._session.start(self._transport.clock())
            self._flush()
        if not self._virtual:
            self._thread = threading.Thread(target=self._io_loop, name=f"roverlink-io {self.url}", daemon=True)
            self._thread.start()
        s = self._session
        self._wait(lambda: s.ready or s.error is not None or self._io_error is not None, timeout_s)
        with self._lock:
            if s.error is not None:
                raise s.error
            if self._io_error is not None:
                raise self._io_error
            if not s.ready:
                d = s.decoder.stats
                raise ConnectTimeoutError(
                    self.url,
                    self._options.baud,
                    timeout_s,
                    bytes_received=d.bytes_received,
                    frames_ok=d.frames_ok,
                    identity_seen=s.identities_seen > 0,
                )
            assert s.identity is not None
            if (
                self._options.feedback_mode is FeedbackMode.LOCKSTEP
                and s.identity.feedback_mode is not FeedbackMode.LOCKSTEP
            ):
                raise UnsupportedError(
                    f"lockstep feedback was asked for, but {s.identity.robot_name or 'the firmware'} on {self.url} "
                    "has no LOCKSTEP capability: connect with mode='stream'"
                )
            s.set_kinematics(self._resolve_kinematics())

    def _resolve_kinematics(self) -> DiffDrive | Ackermann | None:
        s = self._session
        assert s.identity is not None and s.config is not None
        caps = s.identity.capabilities
        if self._user_kinematics is not None:
            kin: DiffDrive | Ackermann | None = self._user_kinematics
        else:
            name = self._profile_name
            if name is None:
                name = self._transport.profile
            prof = get_profile(name) if name is not None else profile_for_example(s.identity.robot_name)
            kin = kinematics_for(prof, s.config) if prof is not None else None
        if isinstance(kin, DiffDrive) and not caps & Capability.DIFF_DRIVE:
            raise UnsupportedError(
                f"differential-drive kinematics, but the firmware on {self.url} cannot drive two wheels"
            )
        if isinstance(kin, Ackermann) and not caps & Capability.ACKERMANN:
            raise UnsupportedError(f"Ackermann kinematics, but the firmware on {self.url} has no steering")
        return kin

    # == the runner ================================================================================
    def _flush(self) -> None:
        data = self._session.outgoing()
        if data:
            self._transport.write(data)

    def _process(self, data: bytes) -> None:
        """Under the lock: feed the session, run its timers, send what it wants sent."""
        s = self._session
        now = self._transport.clock()
        s.receive(data, now)
        s.poll(now)
        self._flush()
        events = s.take_events()
        if events:
            self._pending_callbacks.extend(events)
        self._cond.notify_all()

    def _io_loop(self) -> None:
        transport = self._transport
        while not self._stop.is_set():
            with self._lock:
                now = transport.clock()
                timeout = min(_IO_POLL_S, max(0.001, self._session.next_deadline(now) - now))
            try:
                data = transport.read(timeout)
                with self._lock:
                    if self._stop.is_set():
                        break
                    self._process(data)
            except TransportError as exc:
                with self._lock:
                    self._io_error = exc
                    self._cond.notify_all()
                log.error("RoverLink I/O stopped: %s", exc)
                break
            self._dispatch()

    def _wait(self, predicate: Callable[[], bool], timeout_s: float) -> bool:
        """Wait until `predicate()` (evaluated under the lock) or `timeout_s` passes on the session's clock."""
        if not self._virtual:
            deadline = time.monotonic() + timeout_s
            with self._cond:
                while not predicate():
                    left = deadline - time.monotonic()
                    if left <= 0 or self._closed or self._io_error is not None:
                        return predicate()
                    self._cond.wait(min(left, 0.1))
                return True
        transport = self._transport
        with self._lock:
            deadline = transport.clock() + timeout_s
        while True:
            with self._lock:
                if predicate():
                    return True
                now = transport.clock()
                if now >= deadline - 1e-9 or self._closed:
                    return False
                step = min(deadline, self._session.next_deadline(now), now + _VIRTUAL_STEP_S) - now
                try:
                    data = transport.read(max(step, 0.0002))
                except TransportError as exc:
                    self._io_error = exc
                    return predicate()
                self._process(data)
            self._dispatch()

    def _dispatch(self) -> None:
        """Run user callbacks for the events of the last step (never with the lock held)."""
        with self._lock:
            events, self._pending_callbacks = self._pending_callbacks, []
        for event in events:
            try:
                if isinstance(event, FeedbackReceived):
                    for fb_cb in list(self._on_feedback):
                        fb_cb(event.sample)
                elif isinstance(event, ResetDetected):
                    error = SessionResetError(event.old_boot_id, event.new_boot_id, event.why)
                    for reset_cb in list(self._on_reset):
                        reset_cb(error)
                elif isinstance(event, FailsafeEntered):
                    for fs_cb in list(self._on_failsafe):
                        fs_cb(event.reason)
                elif isinstance(event, LogReceived):
                    log.log(_LOG_LEVELS.get(event.level, logging.INFO), "board: %s", event.text)
                    for log_cb in list(self._on_log):
                        log_cb(event.level, event.text)
                elif isinstance(event, Failed):
                    log.error("RoverLink session failed: %s", event.error)
            except Exception:
                log.exception("a RoverLink callback raised (ignored)")

    # == properties ================================================================================
    @property
    def url(self) -> str:
        return self._transport.url

    @property
    def transport(self) -> Transport:
        return self._transport

    @property
    def emulator(self) -> Any:
        """The in-process emulator behind an emu:// URL (the transport's `device`; None otherwise).

        On the virtual clock use it freely; on the real clock an I/O thread drives it, so wrap
        access in `with robot.transport.locked() as emu:`."""
        return self._transport.device

    @property
    def virtual_clock(self) -> bool:
        """True on an emulator's virtual clock: time moves only while the robot waits or sleeps."""
        return self._virtual

    @property
    def closed(self) -> bool:
        return self._closed

    @property
    def identity(self) -> RobotIdentity:
        """Firmware version, board, spec hash, capabilities and boot_id of the current session."""
        with self._lock:
            self._check_open()
            identity = self._session.identity
            assert identity is not None
            return identity

    @property
    def config(self) -> RobotConfig:
        """The board's configuration as last read or written (see `read_config()` for a fresh copy)."""
        with self._lock:
            self._check_open()
            config = self._session.config
            assert config is not None
            return config

    @property
    def kinematics(self) -> DiffDrive | Ackermann | None:
        with self._lock:
            return self._session.kinematics

    @property
    def armed(self) -> bool:
        """The host's belief: ARM acknowledged and no failsafe, reset or DISARM since."""
        with self._lock:
            return self._session.armed

    @property
    def failsafe(self) -> FailsafeReason | None:
        """The latched FAILSAFE reason (None when not in failsafe)."""
        with self._lock:
            return self._session.failsafe

    @property
    def state(self) -> str:
        """ "connecting", "disarmed", "armed", "failsafe", "incompatible" or "closed"."""
        with self._lock:
            s = self._session
            if self._closed:
                return "closed"
            if s.state is not LinkState.OPEN:
                return str(s.state.value)
            if s.failsafe is not None:
                return "failsafe"
            return "armed" if s.armed else "disarmed"

    @property
    def feedback(self) -> FeedbackSample | None:
        """The latest FEEDBACK (None before the first)."""
        with self._lock:
            return self._session.latest

    @property
    def feedback_age_s(self) -> float | None:
        """Seconds since the last FEEDBACK arrived (None before the first): a board in its bootloader,
        a cut cable or a lockstep robot with no command in flight all go quiet."""
        with self._lock:
            last = self._session.last_feedback_s
            return None if last is None else self._transport.clock() - last

    @property
    def stats(self) -> LinkStatistics:
        """Link statistics of the host side (frames, errors, retries, NACKs, RTT, clock sync, resets)."""
        with self._lock:
            return self._session.stats(self._transport.clock())

    @property
    def watchdog_s(self) -> float:
        """Watchdog period the board granted."""
        with self._lock:
            return self._session.watchdog_s

    @property
    def command_timeout_s(self) -> float:
        return self._options.command_timeout

    @property
    def mode(self) -> str:
        with self._lock:
            return "lockstep" if self._session.feedback_mode is FeedbackMode.LOCKSTEP else "stream"

    def now(self) -> float:
        """The session's clock in seconds (the host's monotonic clock, or the emulator's virtual time)."""
        return self._transport.clock()

    def mcu_to_host_s(self, mcu_time_us: int) -> float:
        """Host time of an (unwrapped) MCU timestamp, from PING/PONG time sync."""
        with self._lock:
            return self._session.clock.to_host_s(mcu_time_us)

    # == arming ====================================================================================
    def arm(self, timeout_s: float = 2.0, *, wait_esc: bool = True) -> None:
        """Enable the motors (ARM with this session's boot_id); clears a latched FAILSAFE.

        Also acknowledges a reset reported since the last command. On a robot with an ESC still in
        its power-up arming window, waits for the window to end first (wait_esc=False: don't; the
        board then holds neutral until it ends). Raises NackError, RequestTimeoutError, SessionResetError.
        """
        with self._lock:
            self._check_usable()
            self._session.take_reset()
        if not self._wait(lambda: self._session.ready or self._broken(), timeout_s):
            self._raise_broken()
            raise RequestTimeoutError("ARM", 0, timeout_s)
        self._raise_broken()
        if wait_esc:
            left = self._esc_window_left()
            if left > 0:
                self.sleep(left)
        with self._lock:
            identity = self._session.identity
            assert identity is not None
            msg = Arm(boot_id=identity.boot_id)
        self._request(msg)

    def _esc_window_left(self) -> float:
        with self._lock:
            s = self._session
            if s.identity is None or s.config is None or not s.identity.capabilities & Capability.ESC:
                return 0.0
            uptime_s = s.identity.uptime_ms / 1000 + (self._transport.clock() - s.identity.received_s)
            return max(0.0, s.config.esc_arm_ms / 1000 - uptime_s + 0.02)

    def disarm(self) -> None:
        """Disable the motors (the configured safe state). Also clears a latched FAILSAFE."""
        with self._lock:
            self._check_usable()
            self._session.release()
        self._request(Disarm())

    # == driving ===================================================================================
    def drive(
        self, linear_m_s: float, angular_rad_s: float, *, clamp: bool | None = None, hold_s: float | None = None
    ) -> None:
        """Drive with a body twist: forward speed (m/s) and turn rate (rad/s, counter-clockwise).

        Differential drive: wheel speeds from the track width. Ackermann: the steering angle that
        gives this turn rate at this speed. Beyond the limits raises CommandRangeError, or with
        clamp=True scales both wheels down together (the path's curvature is kept).
        The command stays live for `hold_s` (default command_timeout_s): renew it before then.
        """
        linear = _finite("linear_m_s", linear_m_s)
        angular = _finite("angular_rad_s", angular_rad_s)
        clamp = self.clamp if clamp is None else clamp
        with self._lock:
            self._check_open()
            kin = self._session.kinematics
            config = self._session.config
            assert config is not None
            if kin is None:
                raise UnsupportedError(
                    "drive() needs the robot's kinematics: pass profile=... or kinematics=... to Robot.connect, "
                    "or use set_wheel_speeds()/drive_ackermann()"
                )
            limit = config.max_wheel_speed_mm_s / 1000
            if isinstance(kin, DiffDrive):
                left, right = self._diff_speeds(kin, linear, angular, limit, clamp)
                msg: SetWheelSpeeds | SetAckermann = SetWheelSpeeds(_mm(left, limit), _mm(right, limit))
            else:
                steer = self._ackermann_steering(kin, config, linear, angular, clamp)
                speed = self._check_speed("linear_m_s", linear, limit, clamp)
                msg = SetAckermann(_mm(speed, limit), _mrad(steer))
        self._command(msg, hold_s)

    @staticmethod
    def _diff_speeds(kin: DiffDrive, linear: float, angular: float, limit: float, clamp: bool) -> tuple[float, float]:
        half = angular * kin.track_m / 2
        if max(abs(linear - half), abs(linear + half)) <= limit + 1e-9:
            return linear - half, linear + half
        if clamp:
            return kin.wheel_speeds(linear, angular, limit)
        hint = "pass clamp=True to scale both wheels down together (keeps the curvature)"
        if abs(linear) > limit:
            raise CommandRangeError("linear_m_s", linear, f"-{limit:g}..{limit:g} m/s (max_wheel_speed_mm_s)", hint)
        w_max = (limit - abs(linear)) * 2 / kin.track_m
        raise CommandRangeError(
            "angular_rad_s",
            angular,
            f"-{w_max:.3f}..{w_max:.3f} rad/s at linear_m_s={linear:g} (a wheel would exceed {limit:g} m/s)",
            hint,
        )

    def _ackermann_steering(
        self, kin: Ackermann, config: SetConfig, linear: float, angular: float, clamp: bool
    ) -> float:
        if angular == 0:
            return 0.0
        if linear == 0:
            raise CommandRangeError(
                "angular_rad_s", angular, "0 when linear_m_s is 0 (an Ackermann robot cannot turn in place)"
            )
        steer = math.atan(angular * kin.wheelbase_m / linear)
        right, left = steering_limits(config)
        if -right - 1e-9 <= steer <= left + 1e-9:
            return steer
        if clamp:
            return max(-right, min(left, steer))
        # The turn rate this speed allows with the steering at its stop.
        w_left = linear * math.tan(left) / kin.wheelbase_m
        w_right = -linear * math.tan(right) / kin.wheelbase_m
        lo, hi = sorted((w_left, w_right))
        raise CommandRangeError(
            "angular_rad_s",
            angular,
            f"{lo:.3f}..{hi:.3f} rad/s at linear_m_s={linear:g} (steering {-right:.3f}..{left:.3f} rad)",
            "pass clamp=True to steer at the limit instead",
        )

    def _check_speed(self, name: str, value: float, limit: float, clamp: bool) -> float:
        if abs(value) <= limit + 1e-9:
            return value
        if clamp:
            return math.copysign(limit, value)
        raise CommandRangeError(
            name, value, f"-{limit:g}..{limit:g} m/s (max_wheel_speed_mm_s)", "pass clamp=True to clamp instead"
        )

    def set_wheel_speeds(
        self, left_m_s: float, right_m_s: float, *, clamp: bool | None = None, hold_s: float | None = None
    ) -> None:
        """Differential drive: each wheel's rim speed (m/s, positive forward)."""
        left = _finite("left_m_s", left_m_s)
        right = _finite("right_m_s", right_m_s)
        clamp = self.clamp if clamp is None else clamp
        with self._lock:
            self._check_open()
            self._require(Capability.DIFF_DRIVE, "set_wheel_speeds", "drive_ackermann()")
            config = self._session.config
            assert config is not None
            limit = config.max_wheel_speed_mm_s / 1000
            peak = max(abs(left), abs(right))
            if peak > limit + 1e-9:
                if not clamp:
                    name, value = ("left_m_s", left) if abs(left) >= abs(right) else ("right_m_s", right)
                    raise CommandRangeError(
                        name,
                        value,
                        f"-{limit:g}..{limit:g} m/s (max_wheel_speed_mm_s)",
                        "pass clamp=True to scale both wheels down together",
                    )
                left, right = left * limit / peak, right * limit / peak
            msg = SetWheelSpeeds(_mm(left, limit), _mm(right, limit))
        self._command(msg, hold_s)

    def drive_ackermann(
        self, speed_m_s: float, steering_rad: float, *, clamp: bool | None = None, hold_s: float | None = None
    ) -> None:
        """Ackermann: rear-axle speed (m/s) and front-wheel angle (rad, positive turns left)."""
        speed = _finite("speed_m_s", speed_m_s)
        steer = _finite("steering_rad", steering_rad)
        clamp = self.clamp if clamp is None else clamp
        with self._lock:
            self._check_open()
            self._require(Capability.ACKERMANN, "drive_ackermann", "set_wheel_speeds() or drive()")
            config = self._session.config
            assert config is not None
            limit = config.max_wheel_speed_mm_s / 1000
            speed = self._check_speed("speed_m_s", speed, limit, clamp)
            right, left = steering_limits(config)
            if not -right - 1e-9 <= steer <= left + 1e-9:
                if not clamp:
                    raise CommandRangeError(
                        "steering_rad",
                        steer,
                        f"{-right:.3f}..{left:.3f} rad (the servo's configured travel)",
                        "pass clamp=True to steer at the limit instead",
                    )
                steer = max(-right, min(left, steer))
            msg = SetAckermann(_mm(speed, limit), _mrad(steer))
        self._command(msg, hold_s)

    def stop(self) -> None:
        """Zero speed (steering centred). Does nothing when the robot is not armed: it is stopped already."""
        with self._lock:
            self._check_open()
            s = self._session
            if not (s.armed and s.state is LinkState.OPEN):
                s.release()
                return
            caps = s.identity.capabilities if s.identity is not None else Capability(0)
            msg: SetWheelSpeeds | SetAckermann = (
                SetWheelSpeeds(0, 0) if caps & Capability.DIFF_DRIVE else SetAckermann(0, 0)
            )
            self._last_command_seq = s.command(msg, self._transport.clock())
            self._flush()

    def _command(self, msg: SetWheelSpeeds | SetAckermann, hold_s: float | None) -> None:
        if hold_s is not None and not (_finite("hold_s", hold_s) > 0):
            raise CommandRangeError("hold_s", hold_s, "a number of seconds > 0")
        with self._lock:
            self._check_can_drive()
        if self._options.auto_rearm and self._needs_rearm():
            self.arm()
        with self._lock:
            self._check_can_drive()
            s = self._session
            if not s.armed:
                raise self._not_armed_error()
            self._last_command_seq = s.command(msg, self._transport.clock(), hold_s)
            self._flush()

    def _needs_rearm(self) -> bool:
        with self._lock:
            s = self._session
            return not s.armed and s.failsafe in (None, FailsafeReason.COMM_TIMEOUT)

    def _check_can_drive(self) -> None:
        self._check_usable()
        s = self._session
        error = s.take_reset()
        if error is not None:
            raise error
        if s.setpoint_error is not None:
            nack, s.setpoint_error = s.setpoint_error, None
            raise nack

    def _not_armed_error(self) -> NotArmedError:
        s = self._session
        if s.failsafe is not None:
            hint = ""
            if s.failsafe is FailsafeReason.COMM_TIMEOUT:
                hint = (
                    f"no command reached the board for its {s.watchdog_s:g} s watchdog: drive commands expire "
                    f"{self._options.command_timeout:g} s after they are given, so renew them in a loop"
                )
            return FailsafeError(s.failsafe, hint)
        if s.state is LinkState.CONNECTING:
            return NotArmedError("the session is re-opening after a reset; call robot.arm() when ready", "connecting")
        return NotArmedError("the robot is not armed: call robot.arm() first", "disarmed")

    def _require(self, capability: Capability, what: str, instead: str) -> None:
        identity = self._session.identity
        if identity is not None and not identity.capabilities & capability:
            raise UnsupportedError(
                f"{what}() needs a {capability.name} robot; {identity.robot_name or 'this robot'} is not: use {instead}"
            )

    # == feedback ==================================================================================
    def wait_feedback(self, timeout_s: float = 1.0) -> FeedbackSample:
        """The next FEEDBACK. In lockstep mode: the one answering the latest drive command.

        Raises FeedbackTimeoutError (a TimeoutError) if none arrives within `timeout_s`."""
        _finite("timeout_s", timeout_s)
        with self._lock:
            self._check_usable()
            s = self._session
            start = s.latest.index if s.latest is not None else 0
            lockstep = s.feedback_mode is FeedbackMode.LOCKSTEP
            want = self._last_command_seq if lockstep and s.setpoint_live else None

        def arrived() -> bool:
            sample = s.latest
            if sample is None or sample.index <= start:
                return self._broken()
            return want is None or (sample.ack_seq - want) % 256 < 128 or self._broken()

        ok = self._wait(arrived, timeout_s)
        with self._lock:
            self._raise_broken()
            sample = s.latest
            if not ok or sample is None:
                raise FeedbackTimeoutError(timeout_s, lockstep, s.setpoint_live)
            return sample

    def feedback_stream(self, timeout_s: float = 1.0) -> Iterator[FeedbackSample]:
        """Yield FEEDBACK samples as they arrive, until the robot is closed.

        A slow consumer sees the latest sample (some are skipped); use `on_feedback` to see every one."""
        while not self._closed:
            try:
                yield self.wait_feedback(timeout_s)
            except RobotClosedError:
                return

    def on_feedback(self, callback: FeedbackCallback) -> Callable[[], None]:
        """Call `callback(sample)` for every FEEDBACK (on the I/O thread). Returns a function that unsubscribes."""
        return self._subscribe(self._on_feedback, callback)

    def on_reset(self, callback: ResetCallback) -> Callable[[], None]:
        """Call `callback(SessionResetError)` when a board reset is detected."""
        return self._subscribe(self._on_reset, callback)

    def on_failsafe(self, callback: FailsafeCallback) -> Callable[[], None]:
        """Call `callback(reason)` when the board enters FAILSAFE (or the host knows it must have)."""
        return self._subscribe(self._on_failsafe, callback)

    def on_log(self, callback: LogCallback) -> Callable[[], None]:
        """Call `callback(level, text)` for every LOG frame of the firmware (they also go to logging)."""
        return self._subscribe(self._on_log, callback)

    def _subscribe(self, where: list[Any], callback: Any) -> Callable[[], None]:
        with self._lock:
            where.append(callback)

        def unsubscribe() -> None:
            with self._lock:
                if callback in where:
                    where.remove(callback)

        return unsubscribe

    def sleep(self, seconds: float) -> None:
        """Wait `seconds` on the session's clock: wall time, or virtual time with an emu://...?clock=virtual
        robot, where this is what moves the emulator forward (so the same robot code runs in tests)."""
        _finite("seconds", seconds)
        if seconds < 0:
            raise CommandRangeError("seconds", seconds, "a number of seconds >= 0")
        with self._lock:
            self._check_open()
        self._wait(lambda: self._closed, seconds)

    # == configuration =============================================================================
    def read_config(self) -> RobotConfig:
        """Fetch the configuration from the board (GET_CONFIG)."""
        reply = self._request(GetConfig())
        assert isinstance(reply, Config)
        return self.config

    def set_config(self, **changes: Any) -> RobotConfig:
        """Change configuration fields (names as in docs/protocol.md CONFIG), e.g.
        `robot.set_config(max_wheel_speed_mm_s=400, safe_state=SafeState.RAMP_DOWN)`.

        Reads the configuration, replaces the fields, sends SET_CONFIG (reliable: applied once) and
        reads it back. Raises CommandRangeError for an unknown field or a value outside its range,
        NackError when the board refuses (its `field` names the field)."""
        names = [f.name for f in SetConfig.FIELDS]
        for key in changes:
            if key not in names:
                raise CommandRangeError("config field", key, f"one of {', '.join(names)}")
        current = self.read_config()
        try:
            wanted = dataclasses.replace(current, **changes)
            wanted.pack()
        except EncodeError as exc:
            raise CommandRangeError(exc.field, exc.value, exc.allowed) from None
        except TypeError as exc:
            raise CommandRangeError("config", changes, str(exc)) from None
        self._request(SetConfig(**wanted.fields()))
        after = self.read_config()
        if after != wanted:
            raise RoverLinkError(f"the board's configuration read back differs from what was set: {after}")
        self._refresh_kinematics()
        return after

    def _refresh_kinematics(self) -> None:
        with self._lock:
            if self._user_kinematics is None and self._session.kinematics is not None:
                pose = self._session.odometry.pose if self._session.odometry is not None else None
                self._session.set_kinematics(self._resolve_kinematics())
                if pose is not None and self._session.odometry is not None:
                    self._session.odometry.reset(pose.x_m, pose.y_m, pose.theta_rad)

    def pid(self, wheel: int = 0) -> PidGains:
        """The velocity PID gains of one wheel (GET_PID)."""
        if not (isinstance(wheel, int) and 0 <= wheel < WHEEL_COUNT):
            raise CommandRangeError("wheel", wheel, f"a wheel index 0..{WHEEL_COUNT - 1}")
        reply = self._request(GetPid(wheel=wheel))
        assert isinstance(reply, Pid)
        return PidGains(reply.kp, reply.ki, reply.kd, reply.kf)

    def set_pid(
        self,
        *,
        kp: float | None = None,
        ki: float | None = None,
        kd: float | None = None,
        kf: float | None = None,
        wheel: int | None = None,
    ) -> PidGains:
        """Change PID gains of one wheel, or every wheel (wheel=None); unnamed gains keep their value.
        Takes effect at the board's next tick (its integrator is reset). Returns the gains read back."""
        if wheel is not None and not (isinstance(wheel, int) and 0 <= wheel < WHEEL_COUNT):
            raise CommandRangeError("wheel", wheel, f"a wheel index 0..{WHEEL_COUNT - 1}, or None for every wheel")
        info = {f.name: f for f in SetPid.FIELDS}
        given = {"kp": kp, "ki": ki, "kd": kd, "kf": kf}
        for name, value in given.items():
            if value is None:
                continue
            _finite(name, value)
            if not info[name].lo <= value <= info[name].hi:
                raise CommandRangeError(name, value, info[name].allowed())
        current = self.pid(wheel or 0)
        gains = dataclasses.replace(current, **{k: float(v) for k, v in given.items() if v is not None})
        target = PID_ALL_WHEELS if wheel is None else wheel
        self._request(SetPid(wheel=target, kp=gains.kp, ki=gains.ki, kd=gains.kd, kf=gains.kf))
        return self.pid(wheel or 0)

    def save_config(self) -> None:
        """Write configuration and PID gains to the board's EEPROM (refused while armed: disarm first)."""
        self._request(SaveConfig())

    def board_link_stats(self) -> LinkStats:
        """The firmware's own link counters (GET_LINK_STATS): what the board received and sent."""
        reply = self._request(GetLinkStats())
        assert isinstance(reply, LinkStats)
        return reply

    def _request(self, msg: Message) -> Message:
        with self._lock:
            self._check_usable()
            s = self._session
            req: Request = s.submit(msg, self._transport.clock())
            self._flush()
            budget = req.tries * req.timeout_s + 0.5
            if s.state is not LinkState.OPEN:
                budget += 5.0  # re-opening after a reset first
        self._wait(lambda: req.done or self._broken(), budget)
        with self._lock:
            if not req.done:
                s.cancel(req)
                self._raise_broken()
            if req.error is not None:
                if isinstance(req.error, SessionResetError):
                    s.take_reset()  # told now, through this exception
                raise req.error
            assert req.reply is not None
            return req.reply

    # == state checks ==============================================================================
    def _check_open(self) -> None:
        if self._closed:
            raise RobotClosedError(self.url)

    def _broken(self) -> bool:
        return self._closed or self._io_error is not None or self._session.error is not None

    def _raise_broken(self) -> None:
        self._check_open()
        if self._io_error is not None:
            raise self._io_error
        if self._session.error is not None:
            raise self._session.error

    def _check_usable(self) -> None:
        self._raise_broken()

    # == closing ===================================================================================
    def close(self) -> None:
        """Disarm (best effort), stop the I/O thread and release the port. Idempotent."""
        self._shutdown(disarm=True)

    def _shutdown(self, disarm: bool) -> None:
        with self._lock:
            if self._closed:
                return
            s = self._session
            should_disarm = disarm and s.state is LinkState.OPEN and (s.armed or s.setpoint_live)
        if should_disarm and self._io_error is None:
            with self._lock:
                s.release()
                req = s.submit(Disarm(), self._transport.clock(), tries=2, timeout_s=0.1)
                try:
                    self._flush()
                except TransportError:
                    req.done = True
            self._wait(lambda: req.done or self._broken(), 0.3)
        with self._lock:
            self._closed = True
            self._session.close()
            self._stop.set()
            self._cond.notify_all()
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=2.0)
        self._thread = None
        self._transport.close()

    def __enter__(self) -> Robot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __del__(self) -> None:
        # A robot dropped without close(): stop the thread so the port is released.
        if not getattr(self, "_closed", True):
            self._stop.set()

    def __repr__(self) -> str:
        return f"<Robot {self.url} {self.state}>"


def _mm(speed_m_s: float, limit_m_s: float) -> int:
    mm = round(speed_m_s * 1000)
    cap = round(limit_m_s * 1000)
    return max(-cap, min(cap, mm))


def _mrad(angle_rad: float) -> int:
    return max(-1571, min(1571, round(angle_rad * 1000)))


_LOG_LEVELS = {
    LogLevel.DEBUG: logging.DEBUG,
    LogLevel.INFO: logging.INFO,
    LogLevel.WARN: logging.WARNING,
    LogLevel.ERROR: logging.ERROR,
}

__all__ = ["KinematicsError", "OdometryView", "Robot"]
