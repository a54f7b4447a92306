"""A robot file's contents as frozen dataclasses, and the firmware figures derived from them.

The file is in SI units; `config()` and `pid_gains()` turn it into the SET_CONFIG / SET_PID the
firmware takes (mm/s, cdeg, us), `capabilities()` into the flags its firmware reports, and
`wiring` is the same pin assignment type the reference profiles carry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from protocol.generated.enums import Board, Capability, FeedbackMode, LightsMode, SafeState
from protocol.generated.messages import SetConfig, SetPid
from protocol.generated.profiles import Wiring
from protocol.sensors import Mount, RobotSensors


@dataclass(frozen=True)
class Drive:
    kind: str
    """differential or ackermann."""
    driver: str
    """TB6612, L298N, BTS7960 or ESC+servo."""
    motor_invert: tuple[bool, ...]
    """Per wheel channel."""

    @property
    def channels(self) -> int:
        """Wheel channels: two for a differential robot, one (the ESC's motor) for a car."""
        return 2 if self.kind == "differential" else 1


@dataclass(frozen=True)
class Esc:
    min_pulse_s: float = 0.001
    neutral_pulse_s: float = 0.0015
    max_pulse_s: float = 0.002
    arm_s: float = 0.0


@dataclass(frozen=True)
class Steering:
    center_deg: float = 90.0
    min_deg: float = 90.0
    max_deg: float = 90.0
    step_deg: float = 0.0
    min_pulse_s: float = 0.0005
    max_pulse_s: float = 0.0025


@dataclass(frozen=True)
class Encoders:
    counts_per_rev: int
    decoding: str
    invert: tuple[bool, ...]
    """Per wheel channel (none without encoders)."""


@dataclass(frozen=True)
class Geometry:
    wheel_diameter_m: float
    track_m: float
    wheelbase_m: float
    gear_ratio: float


@dataclass(frozen=True)
class Limits:
    max_wheel_speed_m_s: float
    accel_m_s2: float
    decel_m_s2: float
    max_effort: float
    watchdog_s: float
    safe_state: str


GAIN_NAMES = ("kp", "ki", "kd", "kf", "ks")


@dataclass(frozen=True)
class Pid:
    """The speed loop's gains. kp..ks are the first wheel channel's, which are every wheel's unless
    the file gives a key as a list; `per_wheel` has (kp, ki, kd, kf, ks) for each wheel channel
    (empty: every wheel has kp..ks)."""

    kp: float
    ki: float
    kd: float
    kf: float
    ks: float = 0.0
    per_wheel: tuple[tuple[float, float, float, float, float], ...] = ()

    def of_wheel(self, wheel: int) -> tuple[float, float, float, float, float]:
        """(kp, ki, kd, kf, ks) of one wheel channel."""
        if wheel < len(self.per_wheel):
            return self.per_wheel[wheel]
        return (self.kp, self.ki, self.kd, self.kf, self.ks)

    @property
    def differ(self) -> bool:
        """The wheels' gains are not all the same."""
        return len(set(self.per_wheel)) > 1


@dataclass(frozen=True)
class Feedback:
    mode: str
    rate_hz: float
    lockstep: bool


@dataclass(frozen=True)
class SerialSensor:
    """A lidar or an IMU on a host serial port, and where it sits (REP-103, from the pose point)."""

    model: str
    port: str
    baud: int
    """0: the model's datasheet default."""
    x_m: float
    y_m: float
    z_m: float
    yaw_deg: float


@dataclass(frozen=True)
class Camera:
    model: str
    source: str
    width: int
    height: int
    hfov_deg: float
    """0: the model's."""
    fx: float
    fy: float
    cx: float
    cy: float
    x_m: float
    y_m: float
    z_m: float
    yaw_deg: float


@dataclass(frozen=True)
class Footprint:
    """The body: a disc (radius_m), a box (length_m x width_m) or a polygon, in metres."""

    radius_m: float | None
    length_m: float | None
    width_m: float | None
    polygon_m: tuple[tuple[float, float], ...] | None
    x_m: float

    def disc(self) -> tuple[float, float]:
        """(radius, centre x) of the smallest disc around the pose-point axis that covers the body
        (what collision checks that model the body as a disc take)."""
        if self.radius_m is not None:
            return self.radius_m, self.x_m
        if self.length_m is not None and self.width_m is not None:
            return math.hypot(self.length_m, self.width_m) / 2, self.x_m
        pts = self.polygon_m or ((0.0, 0.0),)
        cx = (max(x for x, _ in pts) + min(x for x, _ in pts)) / 2
        cy = (max(y for _, y in pts) + min(y for _, y in pts)) / 2
        return max(math.hypot(x - cx, y - cy) for x, y in pts), cx


@dataclass(frozen=True)
class Calibration:
    """Measured values (written by calibration); None: not measured, the nominal one applies."""

    wheel_diameter_m: float | None = None
    track_m: float | None = None
    counts_per_rev: int | None = None
    steering_trim_deg: float = 0.0


Values = tuple[tuple[str, float], ...]
"""A section's keys and values, in the schema's order (an absent optional key left out)."""


@dataclass(frozen=True)
class Emulator:
    """[emulator.*]: the emulator's physics of the robot, as data (the emulator builds its models
    from them: emulator/plant/params.py). None: the section is left out (the nearest reference
    robot's applies)."""

    motor: Values | None = None
    body: Values | None = None
    esc: Values | None = None
    servo: Values | None = None


def _bits(flags: tuple[bool, ...]) -> int:
    return sum(1 << i for i, on in enumerate(flags) if on)


@dataclass(frozen=True)
class RobotFile:
    """One robot, as its file describes it (see docs/robot-file.md)."""

    path: str
    name: str
    description: str
    board: str
    """uno, mega2560, pico or native."""
    drive: Drive
    esc: Esc | None
    steering: Steering | None
    encoders: Encoders
    geometry: Geometry
    limits: Limits
    pid: Pid
    feedback: Feedback
    wiring: Wiring
    """Which pin serves which part (the type the reference profiles carry)."""
    lights: str
    """[lights] mode: auto or off."""
    lidar: SerialSensor | None
    imu: SerialSensor | None
    camera: Camera | None
    footprint: Footprint
    calibration: Calibration
    example: str = ""
    """[firmware] example: the library's example sketch to build from ("": the drive and driver's)."""
    emulator: Emulator = Emulator()

    # -- what the firmware and the host use: calibrated values where measured ------------------
    @property
    def wheel_diameter_m(self) -> float:
        return self.calibration.wheel_diameter_m or self.geometry.wheel_diameter_m

    @property
    def track_m(self) -> float:
        return self.calibration.track_m or self.geometry.track_m

    @property
    def counts_per_rev(self) -> int:
        return self.calibration.counts_per_rev or self.encoders.counts_per_rev

    @property
    def metres_per_count(self) -> float:
        return math.pi * self.wheel_diameter_m / self.counts_per_rev

    def board_enum(self) -> Board:
        return Board[self.board.upper()]

    def feedback_mode(self) -> FeedbackMode:
        return FeedbackMode[self.feedback.mode.upper()]

    def lights_mode(self) -> LightsMode:
        """The turn signals' power-up mode ([lights] mode; AUTO without LEDs)."""
        return LightsMode[self.lights.upper()]

    def capabilities(self) -> Capability:
        # The Pico's firmware keeps no configuration (docs/firmware.md, "Raspberry Pi Pico").
        caps = Capability(0) if self.board == "pico" else Capability.EEPROM
        if self.drive.kind == "differential":
            caps |= Capability.DIFF_DRIVE
        else:
            caps |= Capability.ACKERMANN | Capability.STEERING_SERVO | Capability.ESC
        if self.wiring.encoders:
            caps |= Capability.ENCODERS
        if self.wiring.led_pins:
            caps |= Capability.TURN_SIGNALS
        if self.feedback.lockstep:
            caps |= Capability.LOCKSTEP
        return caps

    def config(self) -> SetConfig:
        """The firmware's SET_CONFIG defaults, in its units."""
        esc, steer, lim = self.esc or Esc(), self.steering or Steering(), self.limits
        trim = self.calibration.steering_trim_deg if self.steering is not None else 0.0

        def us(s: float) -> int:
            return round(s * 1e6)

        def cdeg(d: float) -> int:
            return round(d * 100)

        return SetConfig(
            watchdog_ms=round(lim.watchdog_s * 1000),
            safe_state=SafeState[lim.safe_state.upper()],
            accel_limit_mm_s2=round(lim.accel_m_s2 * 1000),
            decel_limit_mm_s2=round(lim.decel_m_s2 * 1000),
            max_wheel_speed_mm_s=round(lim.max_wheel_speed_m_s * 1000),
            max_effort_permille=round(lim.max_effort * 1000),
            encoder_cpr=self.counts_per_rev,
            encoder_invert=_bits(self.encoders.invert),
            motor_invert=_bits(self.drive.motor_invert),
            wheel_diameter_um=round(self.wheel_diameter_m * 1e6),
            steering_center_cdeg=cdeg(steer.center_deg + trim),
            # The trim moves the servo's travel with its centre, as calibration does on the board.
            steering_min_cdeg=max(0, cdeg(steer.min_deg + trim)),
            steering_max_cdeg=min(SetConfig.STEERING_MAX_CDEG_MAX, cdeg(steer.max_deg + trim)),
            steering_step_cdeg=cdeg(steer.step_deg),
            servo_min_us=us(steer.min_pulse_s),
            servo_max_us=us(steer.max_pulse_s),
            esc_min_us=us(esc.min_pulse_s),
            esc_neutral_us=us(esc.neutral_pulse_s),
            esc_max_us=us(esc.max_pulse_s),
            esc_arm_ms=round(esc.arm_s * 1000),
            feedback_hz=round(self.feedback.rate_hz),
        )

    def pid_gains(self, wheel: int = 255) -> SetPid:
        """SET_PID with the file's gains of `wheel` (255: all wheels, with the first channel's gains:
        the firmware's compiled default is one set; per-wheel gains reach the board at connect)."""
        return SetPid(wheel, *self.pid.of_wheel(0 if wheel == 255 else wheel))

    def pid_per_wheel(self) -> tuple[SetPid, ...]:
        """One SET_PID per wheel channel, with that wheel's gains."""
        return tuple(self.pid_gains(w) for w in range(self.drive.channels))

    def mounts(self) -> tuple[Mount, ...]:
        """The sensors' mounts, as protocol.sensors describes them (lidar, imu, camera)."""
        out = []
        for kind, s in (("lidar", self.lidar), ("imu", self.imu), ("camera", self.camera)):
            if s is not None:
                out.append(Mount(s.model, kind, s.x_m, s.y_m, s.z_m, s.yaw_deg))
        return tuple(out)

    def sensors(self) -> RobotSensors:
        """Footprint and mounts in the form the reference robots' sensors take (emulator, geometry)."""
        radius, x = self.footprint.disc()
        return RobotSensors(self.name, radius, x, self.mounts())
