"""The session's state, and what the robot may ask of it (read-only views and one-shot errors).

The transitions are the Session's (core.py); this half holds what they change, so that everything
above the session reads it through properties and methods and nothing writes it from outside.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING

from host_sdk.errors import (
    ConnectTimeoutError,
    FailsafeError,
    NackError,
    NotArmedError,
    RoverLinkError,
    SessionResetError,
)
from host_sdk.framing import FrameDecoder
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.odometry import Pose
from host_sdk.session.events import Event, LinkState, SessionOptions
from host_sdk.session.feedback import FeedbackTracker
from host_sdk.session.types import FeedbackSample, RobotIdentity
from host_sdk.timesync import ClockSync
from protocol.generated.enums import Capability, FailsafeReason, FeedbackMode
from protocol.generated.messages import SetAckermann, SetConfig, SetWheelSpeeds

if TYPE_CHECKING:
    from host_sdk.session.requests import Request


@dataclass(slots=True)
class _Counters:
    frames_sent: int = 0
    bytes_sent: int = 0
    seq_gaps: int = 0
    feedback_received: int = 0
    setpoints_sent: int = 0
    keepalives_sent: int = 0
    hellos_sent: int = 0
    requests_sent: int = 0
    retries: int = 0
    request_timeouts: int = 0
    pings_sent: int = 0
    pongs_received: int = 0
    resets_detected: int = 0
    reconnects: int = 0
    nacks: dict[str, int] = field(default_factory=dict)
    rtts: deque[float] = field(default_factory=lambda: deque(maxlen=64))
    rtt_count: int = 0

    def counts(self) -> dict[str, int]:
        """The counts LinkStatistics reports under the same names (every int field but rtt_count)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name not in ("nacks", "rtts", "rtt_count")}


class SessionState:
    """What the host knows of one link (it outlives board resets: each reset opens a new firmware session)."""

    def __init__(self, options: SessionOptions, kinematics: DiffDrive | Ackermann | None = None) -> None:
        self.options = options
        self._state = LinkState.CONNECTING
        self._identity: RobotIdentity | None = None
        self._config: SetConfig | None = None
        self._armed = False
        self._failsafe: FailsafeReason | None = None
        """Latched FAILSAFE the board reported (or the host predicted); None when not in failsafe."""
        self._failsafe_predicted = False
        self._error: RoverLinkError | None = None
        """Why the session cannot go on (incompatible firmware)."""
        self._setpoint_error: NackError | None = None
        """A setpoint the board refused (out of range, unsupported): raised on the user's next command."""
        self._latest: FeedbackSample | None = None
        self.clock = ClockSync()
        self._feedback = FeedbackTracker(kinematics)
        self.decoder = FrameDecoder()
        self.started_s: float | None = None
        self.ready_s: float | None = None
        self._opened_s: float | None = None
        self._last_rx_s: float | None = None
        self._last_feedback_s: float | None = None
        self._identities_seen = 0
        self._n = _Counters()
        self._out: list[bytes] = []
        self._events: list[Event] = []
        self._tx_seq = 0
        self._rx_seq: int | None = None
        self._next_hello = 0.0
        self._hello_seqs: dict[int, int] = {}  # HELLO seq -> the GET_CONFIG seq sent right behind it
        self._handshake_config_seqs: set[int] = set()
        self._opened_once = False
        self._queue: deque[Request] = deque()
        self._inflight: Request | None = None
        self._last_reliable_key: tuple[int, int] | None = None
        self._setpoint: SetWheelSpeeds | SetAckermann | None = None
        self._setpoint_seq = -1
        self._setpoint_expires = 0.0
        self._setpoint_sent = 0.0
        self._last_tx = 0.0
        self._pings: dict[int, float] = {}
        self._next_ping = 0.0
        self._reset_pending: tuple[int, int | None, str] | None = None
        self._rearm_after_open = False
        self._config_fresh = False
        self._ready_announced = False

    @property
    def setpoint_live(self) -> bool:
        return self._setpoint is not None

    @property
    def last_setpoint_seq(self) -> int:
        return self._setpoint_seq

    def take_reset(self) -> SessionResetError | None:
        """The SessionResetError to raise on the user's next command (once), if a reset happened."""
        pending, self._reset_pending = self._reset_pending, None
        if pending is None:
            return None
        old, new, why = pending
        if new is None and self._identity is not None and self._identity.boot_id != old:
            new = self._identity.boot_id
        return SessionResetError(old, new, why)

    # == what the robot asks ========================================================================
    def take_command_error(self) -> RoverLinkError | None:
        """What the user's next drive command must raise, once: a reset not yet reported, or a
        setpoint the board refused."""
        error: RoverLinkError | None = self.take_reset()
        if error is None:
            error, self._setpoint_error = self._setpoint_error, None
        return error

    def not_armed_error(self) -> NotArmedError:
        """The error for a drive command while not armed, saying why and what to do."""
        if self._failsafe is not None:
            hint = ""
            if self._failsafe is FailsafeReason.COMM_TIMEOUT:
                hint = (
                    f"no command reached the board for its {self.watchdog_s:g} s watchdog: drive commands expire "
                    f"{self.options.command_timeout:g} s after they are given, so renew them in a loop"
                )
            return FailsafeError(self._failsafe, hint)
        if self._state is LinkState.CONNECTING:
            return NotArmedError("the session is re-opening after a reset; call robot.arm() when ready", "connecting")
        return NotArmedError("the robot is not armed: call robot.arm() first", "disarmed")

    def wants_rearm(self) -> bool:
        """Not armed, and nothing but a reset or a watchdog failsafe keeps it so (auto_rearm's cue)."""
        return not self._armed and self._failsafe in (None, FailsafeReason.COMM_TIMEOUT)

    def connect_timeout_error(self, timeout_s: float) -> ConnectTimeoutError:
        """Why no session opened within `timeout_s`, from what was heard."""
        d = self.decoder.stats
        o = self.options
        return ConnectTimeoutError(
            o.url,
            o.baud,
            timeout_s,
            bytes_received=d.bytes_received,
            frames_ok=d.frames_ok,
            identity_seen=self._identities_seen > 0,
        )

    def esc_window_left(self, now: float) -> float:
        """Seconds until an ESC robot's power-up arming window ends (0 without an ESC)."""
        ident, config = self._identity, self._config
        if ident is None or config is None or not ident.capabilities & Capability.ESC:
            return 0.0
        uptime_s = ident.uptime_ms / 1000 + (now - ident.received_s)
        return max(0.0, config.esc_arm_ms / 1000 - uptime_s + 0.02)

    def pose(self) -> Pose | None:
        """The odometry's pose (None without kinematics)."""
        odo = self._feedback.odometry
        return odo.pose if odo is not None else None

    def reset_pose(self, x_m: float, y_m: float, theta_rad: float) -> bool:
        """Set the pose (counting goes on from the next sample); False without kinematics."""
        odo = self._feedback.odometry
        if odo is None:
            return False
        odo.reset(x_m, y_m, theta_rad)
        return True

    def mcu_to_host_s(self, mcu_time_us: float) -> float:
        """Host time of an unwrapped MCU timestamp (PING/PONG time sync)."""
        return self.clock.to_host_s(mcu_time_us)

    # == state (read-only: the session changes it, nothing else) ===================================
    @property
    def state(self) -> LinkState:
        return self._state

    @property
    def identity(self) -> RobotIdentity | None:
        """The IDENTITY that opened the current session."""
        return self._identity

    @property
    def config(self) -> SetConfig | None:
        """The board's configuration as last read or written."""
        return self._config

    @property
    def armed(self) -> bool:
        return self._armed

    @property
    def failsafe(self) -> FailsafeReason | None:
        """Latched FAILSAFE the board reported (or the host predicted); None when not in failsafe."""
        return self._failsafe

    @property
    def error(self) -> RoverLinkError | None:
        """Why the session cannot go on (incompatible firmware, a broken link)."""
        return self._error

    @property
    def latest(self) -> FeedbackSample | None:
        """The latest FEEDBACK."""
        return self._latest

    @property
    def last_feedback_s(self) -> float | None:
        return self._last_feedback_s

    @property
    def kinematics(self) -> DiffDrive | Ackermann | None:
        return self._feedback.kinematics

    @property
    def ready(self) -> bool:
        return self._state is LinkState.OPEN and self._config_fresh

    @property
    def boot_id(self) -> int | None:
        return self._identity.boot_id if self._identity is not None else None

    @property
    def watchdog_s(self) -> float:
        if self._identity is not None and self._identity.watchdog_ms:
            return self._identity.watchdog_ms / 1000
        return self.options.watchdog_s

    @property
    def feedback_mode(self) -> FeedbackMode:
        return self._identity.feedback_mode if self._identity is not None else self.options.feedback_mode
