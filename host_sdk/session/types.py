"""Snapshots the session hands out: identity, feedback samples, PID gains, link statistics.

All are frozen dataclasses: a snapshot never changes under the reader, whichever thread made it.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields

from host_sdk.pose import Pose
from protocol.generated.enums import Board, Capability, FailsafeReason, FeedbackMode, Status
from protocol.generated.messages import Identity, SetConfig
from protocol.generated.structs import DecoderCountersSnapshot

RobotConfig = SetConfig
"""The firmware's configuration: the fields of CONFIG / SET_CONFIG, typed and range-checked.
Change it with `Robot.set_config(**changes)`; `dataclasses.replace` makes a modified copy."""


@dataclass(frozen=True, slots=True)
class RobotIdentity:
    """What the firmware said about itself in the IDENTITY that opened the session."""

    protocol_version: int
    spec_hash: int
    firmware_version: tuple[int, int, int]
    board: Board
    capabilities: Capability
    boot_id: int
    """Random per boot: a new value means the board was reset."""
    uptime_ms: int
    """Board uptime when it answered the HELLO."""
    robot_name: str
    """The firmware example (sketch) name, e.g. DiffDriveTB6612."""
    watchdog_ms: int
    """Watchdog period granted for this session."""
    feedback_mode: FeedbackMode
    feedback_hz: int
    received_s: float
    """Host clock when the IDENTITY arrived."""

    @classmethod
    def of(cls, msg: Identity, received_s: float) -> RobotIdentity:
        # Every field but received_s is the IDENTITY field of the same name.
        copied = {f.name: getattr(msg, f.name) for f in fields(cls) if f.name != "received_s"}
        return cls(**copied, received_s=received_s)

    @property
    def version(self) -> str:
        """Firmware version as "major.minor.patch"."""
        return ".".join(str(v) for v in self.firmware_version)

    def can(self, capability: Capability) -> bool:
        return bool(self.capabilities & capability)


@dataclass(frozen=True, slots=True)
class FeedbackSample:
    """One FEEDBACK frame, decoded, unwrapped and mapped to host time.

    Counts are cumulative since the board booted (unwrapped past the i32 wire range, so they
    never jump); a lost FEEDBACK frame loses no counts, the next one carries them.
    """

    index: int
    """How many FEEDBACK frames this robot object has received, this one included."""
    boot_id: int
    received_s: float
    """Host clock when the frame arrived."""
    host_time_s: float
    """Host clock at the MCU tick that produced it (time-synced; `received_s` until the first PONG;
    never earlier than the previous sample's, though the clock fit moves)."""
    mcu_time_us: int
    """MCU clock at that tick, unwrapped."""
    tick: int
    """Control tick counter, unwrapped."""
    status: Status
    failsafe_reason: FailsafeReason
    encoder_counts: tuple[int, ...]
    """Cumulative counts per wheel since boot (forward positive)."""
    wheel_speeds_m_s: tuple[float, ...]
    """Measured wheel rim speeds."""
    efforts: tuple[float, ...]
    """Motor efforts applied, -1..1."""
    steering_rad: float
    """Front-wheel angle commanded (0 without steering)."""
    ack_seq: int
    """seq of the last setpoint the firmware applied."""
    pose: Pose | None
    """Odometry after this sample (None when the robot's kinematics are unknown)."""

    @property
    def armed(self) -> bool:
        return bool(self.status & Status.ARMED)

    @property
    def failsafe(self) -> bool:
        return bool(self.status & Status.FAILSAFE)


@dataclass(frozen=True, slots=True)
class PidGains:
    """Velocity PID gains of one wheel, in the spec's units (permille of full effort per mm/s...)."""

    kp: float
    ki: float
    kd: float
    kf: float
    ks: float = 0.0
    """Static-friction feed-forward: permille added with the setpoint's sign."""


@dataclass(frozen=True, slots=True)
class RttStats:
    last_s: float
    min_s: float
    mean_s: float
    max_s: float
    samples: int


@dataclass(frozen=True, slots=True)
class LinkStatistics(DecoderCountersSnapshot):
    """The host side of the link, counted since the robot object was created.

    The receive counters (frames_ok, crc_errors, cobs_errors, length_errors, unknown_ids,
    value_errors, bytes_discarded) are the spec's decoder counter set, the same the firmware
    reports in LINK_STATS; the rest are the host's own.
    """

    frames_sent: int = 0
    bytes_sent: int = 0
    bytes_received: int = 0
    seq_gaps: int = 0
    """Board frames missing according to their seq (lost or corrupted on the way)."""
    feedback_received: int = 0
    setpoints_sent: int = 0
    """Setpoint frames, keep-alive repeats included."""
    keepalives_sent: int = 0
    paced_late: int = 0
    """Paced lockstep: setpoints sent half their slack or more after their slot on the board's
    tick grid (a period at 100 Hz, where the board holds one ahead; half a period below): the host
    was busy or stalled, and one a little later misses its tick, which then answers no FEEDBACK."""
    hellos_sent: int = 0
    requests_sent: int = 0
    """Reliable requests (first tries)."""
    retries: int = 0
    request_timeouts: int = 0
    nacks: dict[str, int] = field(default_factory=dict)
    """NACKs received, by reason name."""
    pings_sent: int = 0
    pongs_received: int = 0
    rtt: RttStats | None = None
    """PING/PONG round trips (None before the first)."""
    clock_offset_us: float | None = None
    """MCU clock minus host clock now, in microseconds (None before time sync)."""
    clock_drift_ppm: float | None = None
    resets_detected: int = 0
    """Board resets (new boot_id) and lost sessions noticed."""
    reconnects: int = 0
    """Sessions re-opened after a reset."""
    connect_time_s: float | None = None
    """From the first HELLO to the session being ready (identity and config)."""

    @property
    def frames_received(self) -> int:
        """Valid frames received (frames_ok)."""
        return self.frames_ok

    def as_dict(self) -> dict[str, object]:
        return asdict(self)
