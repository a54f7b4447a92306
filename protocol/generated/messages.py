# DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
# spec hash: 0xBDF31659
"""Message classes: frozen, slotted dataclasses with pack() and unpack()."""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import ClassVar

from protocol.generated.enums import Board, Capability, FailsafeReason, FeedbackMode, IdentityReason, LightsMode, LogLevel, NackReason, SafeState, Status
from protocol.codec.message import (
    Delivery,
    Direction,
    FieldInfo,
    Message,
    decode_error,
    first_invalid,
    slot_setter,
)

_new = object.__new__
_BOARD: dict[int, Board] = {int(m): m for m in Board}
_CAPABILITY: dict[int, Capability] = {v: Capability(v) for v in range(0xFF + 1) if not v & ~0xFF}
_FAILSAFEREASON: dict[int, FailsafeReason] = {int(m): m for m in FailsafeReason}
_FEEDBACKMODE: dict[int, FeedbackMode] = {int(m): m for m in FeedbackMode}
_IDENTITYREASON: dict[int, IdentityReason] = {int(m): m for m in IdentityReason}
_LIGHTSMODE: dict[int, LightsMode] = {int(m): m for m in LightsMode}
_LOGLEVEL: dict[int, LogLevel] = {int(m): m for m in LogLevel}
_NACKREASON: dict[int, NackReason] = {int(m): m for m in NackReason}
_SAFESTATE: dict[int, SafeState] = {int(m): m for m in SafeState}
_STATUS: dict[int, Status] = {v: Status(v) for v in range(0x7F + 1) if not v & ~0x7F}

_S_HELLO = struct.Struct("<BIHBB")
_S_PING = struct.Struct("<I")
_S_ARM = struct.Struct("<I")
_S_SET_PID = struct.Struct("<Bfffff")
_S_GET_PID = struct.Struct("<B")
_S_SET_CONFIG = struct.Struct("<HBHHHHHBBIHHHHHHHHHHB")
_S_SET_LIGHTS = struct.Struct("<BBBB")
_S_SET_WHEEL_SPEEDS = struct.Struct("<hh")
_S_SET_ACKERMANN = struct.Struct("<hh")
_S_IDENTITY = struct.Struct("<BI3BBHIIBBHBB")
_S_PONG = struct.Struct("<II")
_S_ACK = struct.Struct("<BB")
_S_NACK = struct.Struct("<BBBB")
_S_PID = struct.Struct("<BBfffff")
_S_CONFIG = struct.Struct("<BHBHHHHHBBIHHHHHHHHHHB")
_S_LINK_STATS = struct.Struct("<BIIIIIIIIIII")
_S_LIGHTS_STATE = struct.Struct("<BBBBBB")
_S_FEEDBACK = struct.Struct("<IIHBHBB2i2h2hh")
_S_LOG = struct.Struct("<B")


@dataclass(frozen=True, slots=True)
class Hello(Message):
    """HELLO (0x01, host to mcu, session): Opens (or restarts) a session. Repeated every HELLO_INTERVAL_MS until IDENTITY arrives. Motors are disabled while the session restarts."""

    MSG_ID: ClassVar[int] = 0x01
    NAME: ClassVar[str] = "HELLO"
    CRC_EXTRA: ClassVar[int] = 0x77
    PAYLOAD_SIZE: ClassVar[int] = 9
    PAYLOAD_MAX: ClassVar[int] = 9
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.SESSION
    WATCHDOG_MS_MAX: ClassVar[int] = 60000
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('protocol_version', 'u8', 'int', 0, 255),
        FieldInfo('spec_hash', 'u32', 'int', 0, 4294967295),
        FieldInfo('watchdog_ms', 'u16', 'int', 0, 60000, unit='ms'),
        FieldInfo('feedback_mode', 'FeedbackMode', 'enum', 0, 1, enum=FeedbackMode),
        FieldInfo('feedback_hz', 'u8', 'int', 0, 255, unit='Hz'),
    )

    protocol_version: int
    """Protocol version the host was built for."""
    spec_hash: int
    """Spec hash the host was built from."""
    watchdog_ms: int
    """Requested watchdog period; 0 = stored default. The firmware clamps it to WATCHDOG_MIN_MS..WATCHDOG_MAX_MS. [ms]"""
    feedback_mode: FeedbackMode
    """Stream or lockstep feedback."""
    feedback_hz: int
    """Requested stream rate; 0 = stored default. Clamped to 1..FEEDBACK_HZ_MAX. [Hz]"""

    def pack(self) -> bytes:
        try:
            if 0 <= self.watchdog_ms <= 60000 and self.feedback_mode in _FEEDBACKMODE and bool not in set(map(type, (self.protocol_version, self.spec_hash, self.watchdog_ms, self.feedback_mode, self.feedback_hz,))):
                return _S_HELLO.pack(self.protocol_version, self.spec_hash, self.watchdog_ms, self.feedback_mode, self.feedback_hz)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> Hello:
        if len(payload) != 9:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 9")
        v = _S_HELLO.unpack(payload)
        feedback_mode = _FEEDBACKMODE.get(v[3])
        if feedback_mode is None:
            raise decode_error(cls, f"feedback_mode {v[3]} is not a value of FeedbackMode")
        self = _new(cls)
        _HELLO_PROTOCOL_VERSION(self, v[0])
        _HELLO_SPEC_HASH(self, v[1])
        _HELLO_WATCHDOG_MS(self, v[2])
        _HELLO_FEEDBACK_MODE(self, feedback_mode)
        _HELLO_FEEDBACK_HZ(self, v[4])
        return self


_HELLO_PROTOCOL_VERSION = slot_setter(Hello, "protocol_version")
_HELLO_SPEC_HASH = slot_setter(Hello, "spec_hash")
_HELLO_WATCHDOG_MS = slot_setter(Hello, "watchdog_ms")
_HELLO_FEEDBACK_MODE = slot_setter(Hello, "feedback_mode")
_HELLO_FEEDBACK_HZ = slot_setter(Hello, "feedback_hz")


@dataclass(frozen=True, slots=True)
class Ping(Message):
    """PING (0x02, host to mcu, session): Time-sync probe; answered by PONG."""

    MSG_ID: ClassVar[int] = 0x02
    NAME: ClassVar[str] = "PING"
    CRC_EXTRA: ClassVar[int] = 0x8B
    PAYLOAD_SIZE: ClassVar[int] = 4
    PAYLOAD_MAX: ClassVar[int] = 4
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.SESSION
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('host_time_us', 'u32', 'int', 0, 4294967295, unit='us'),
    )

    host_time_us: int
    """Host clock at send time (low 32 bits), echoed in PONG. [us]"""

    def pack(self) -> bytes:
        try:
            if bool not in set(map(type, (self.host_time_us,))):
                return _S_PING.pack(self.host_time_us)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> Ping:
        if len(payload) != 4:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 4")
        v = _S_PING.unpack(payload)
        self = _new(cls)
        _PING_HOST_TIME_US(self, v[0])
        return self


_PING_HOST_TIME_US = slot_setter(Ping, "host_time_us")


@dataclass(frozen=True, slots=True)
class Arm(Message):
    """ARM (0x10, host to mcu, reliable): Enables the motors and clears a latched FAILSAFE. Refused unless boot_id names the running boot, so an ARM from a previous session is never applied."""

    MSG_ID: ClassVar[int] = 0x10
    NAME: ClassVar[str] = "ARM"
    CRC_EXTRA: ClassVar[int] = 0x2A
    PAYLOAD_SIZE: ClassVar[int] = 4
    PAYLOAD_MAX: ClassVar[int] = 4
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('boot_id', 'u32', 'int', 0, 4294967295),
    )

    boot_id: int
    """boot_id from this session's IDENTITY."""

    def pack(self) -> bytes:
        try:
            if bool not in set(map(type, (self.boot_id,))):
                return _S_ARM.pack(self.boot_id)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> Arm:
        if len(payload) != 4:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 4")
        v = _S_ARM.unpack(payload)
        self = _new(cls)
        _ARM_BOOT_ID(self, v[0])
        return self


_ARM_BOOT_ID = slot_setter(Arm, "boot_id")


@dataclass(frozen=True, slots=True)
class Disarm(Message):
    """DISARM (0x11, host to mcu, reliable): Disables the motors (safe state) and clears a latched FAILSAFE."""

    MSG_ID: ClassVar[int] = 0x11
    NAME: ClassVar[str] = "DISARM"
    CRC_EXTRA: ClassVar[int] = 0x95
    PAYLOAD_SIZE: ClassVar[int] = 0
    PAYLOAD_MAX: ClassVar[int] = 0
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = ()

    def pack(self) -> bytes:
        return b""

    @classmethod
    def unpack(cls, payload: bytes) -> Disarm:
        if len(payload) != 0:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 0")
        return cls()


@dataclass(frozen=True, slots=True)
class SetPid(Message):
    """SET_PID (0x12, host to mcu, reliable): Sets the velocity PID gains of one wheel (or all). Takes effect at the next control tick; the integrator is reset."""

    MSG_ID: ClassVar[int] = 0x12
    NAME: ClassVar[str] = "SET_PID"
    CRC_EXTRA: ClassVar[int] = 0x34
    PAYLOAD_SIZE: ClassVar[int] = 21
    PAYLOAD_MAX: ClassVar[int] = 21
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('wheel', 'u8', 'int', 0, 255),
        FieldInfo('kp', 'f32', 'float', 0.0, 1000.0, unit='permille/(mm/s)'),
        FieldInfo('ki', 'f32', 'float', 0.0, 1000.0, unit='permille/mm'),
        FieldInfo('kd', 'f32', 'float', 0.0, 1000.0, unit='permille/(mm/s^2)'),
        FieldInfo('kf', 'f32', 'float', 0.0, 1000.0, unit='permille/(mm/s)'),
        FieldInfo('ks', 'f32', 'float', 0.0, 1000.0, unit='permille'),
    )

    wheel: int
    """Wheel index (0..WHEEL_COUNT-1) or PID_ALL_WHEELS."""
    kp: float
    """Proportional gain. [permille/(mm/s)]"""
    ki: float
    """Integral gain (per second of error). [permille/mm]"""
    kd: float
    """Derivative gain, on the measurement. [permille/(mm/s^2)]"""
    kf: float
    """Feed-forward gain on the setpoint. [permille/(mm/s)]"""
    ks: float
    """Static-friction feed-forward: the effort that keeps the wheel turning at the lowest speeds, added with the setpoint's sign. [permille]"""

    def pack(self) -> bytes:
        try:
            if 0.0 <= self.kp <= 1000.0 and 0.0 <= self.ki <= 1000.0 and 0.0 <= self.kd <= 1000.0 and 0.0 <= self.kf <= 1000.0 and 0.0 <= self.ks <= 1000.0 and bool not in set(map(type, (self.wheel, self.kp, self.ki, self.kd, self.kf, self.ks,))):
                return _S_SET_PID.pack(self.wheel, self.kp, self.ki, self.kd, self.kf, self.ks)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> SetPid:
        if len(payload) != 21:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 21")
        v = _S_SET_PID.unpack(payload)
        self = _new(cls)
        _SET_PID_WHEEL(self, v[0])
        _SET_PID_KP(self, v[1])
        _SET_PID_KI(self, v[2])
        _SET_PID_KD(self, v[3])
        _SET_PID_KF(self, v[4])
        _SET_PID_KS(self, v[5])
        return self


_SET_PID_WHEEL = slot_setter(SetPid, "wheel")
_SET_PID_KP = slot_setter(SetPid, "kp")
_SET_PID_KI = slot_setter(SetPid, "ki")
_SET_PID_KD = slot_setter(SetPid, "kd")
_SET_PID_KF = slot_setter(SetPid, "kf")
_SET_PID_KS = slot_setter(SetPid, "ks")


@dataclass(frozen=True, slots=True)
class GetPid(Message):
    """GET_PID (0x13, host to mcu, reliable): Asks for one wheel's PID gains; answered by PID."""

    MSG_ID: ClassVar[int] = 0x13
    NAME: ClassVar[str] = "GET_PID"
    CRC_EXTRA: ClassVar[int] = 0x6F
    PAYLOAD_SIZE: ClassVar[int] = 1
    PAYLOAD_MAX: ClassVar[int] = 1
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('wheel', 'u8', 'int', 0, 255),
    )

    wheel: int
    """Wheel index (0..WHEEL_COUNT-1)."""

    def pack(self) -> bytes:
        try:
            if bool not in set(map(type, (self.wheel,))):
                return _S_GET_PID.pack(self.wheel)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> GetPid:
        if len(payload) != 1:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 1")
        v = _S_GET_PID.unpack(payload)
        self = _new(cls)
        _GET_PID_WHEEL(self, v[0])
        return self


_GET_PID_WHEEL = slot_setter(GetPid, "wheel")


@dataclass(frozen=True, slots=True)
class SetConfig(Message):
    """SET_CONFIG (0x14, host to mcu, reliable): Replaces the whole configuration (read it with GET_CONFIG, change, send back). Validated as a whole: NACK(OUT_OF_RANGE or INVALID_CONFIG, detail = field index) leaves the old one in place."""

    MSG_ID: ClassVar[int] = 0x14
    NAME: ClassVar[str] = "SET_CONFIG"
    CRC_EXTRA: ClassVar[int] = 0xF8
    PAYLOAD_SIZE: ClassVar[int] = 40
    PAYLOAD_MAX: ClassVar[int] = 40
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    WATCHDOG_MS_MIN: ClassVar[int] = 50
    WATCHDOG_MS_MAX: ClassVar[int] = 2000
    ACCEL_LIMIT_MM_S2_MIN: ClassVar[int] = 1
    DECEL_LIMIT_MM_S2_MIN: ClassVar[int] = 1
    MAX_WHEEL_SPEED_MM_S_MIN: ClassVar[int] = 1
    MAX_WHEEL_SPEED_MM_S_MAX: ClassVar[int] = 20000
    MAX_EFFORT_PERMILLE_MAX: ClassVar[int] = 1000
    ENCODER_CPR_MIN: ClassVar[int] = 1
    ENCODER_INVERT_MAX: ClassVar[int] = 3
    MOTOR_INVERT_MAX: ClassVar[int] = 3
    WHEEL_DIAMETER_UM_MIN: ClassVar[int] = 1000
    WHEEL_DIAMETER_UM_MAX: ClassVar[int] = 1000000
    STEERING_CENTER_CDEG_MAX: ClassVar[int] = 18000
    STEERING_MIN_CDEG_MAX: ClassVar[int] = 18000
    STEERING_MAX_CDEG_MAX: ClassVar[int] = 18000
    STEERING_STEP_CDEG_MAX: ClassVar[int] = 9000
    SERVO_MIN_US_MIN: ClassVar[int] = 400
    SERVO_MIN_US_MAX: ClassVar[int] = 2600
    SERVO_MAX_US_MIN: ClassVar[int] = 400
    SERVO_MAX_US_MAX: ClassVar[int] = 2600
    ESC_MIN_US_MIN: ClassVar[int] = 800
    ESC_MIN_US_MAX: ClassVar[int] = 2200
    ESC_NEUTRAL_US_MIN: ClassVar[int] = 800
    ESC_NEUTRAL_US_MAX: ClassVar[int] = 2200
    ESC_MAX_US_MIN: ClassVar[int] = 800
    ESC_MAX_US_MAX: ClassVar[int] = 2200
    ESC_ARM_MS_MAX: ClassVar[int] = 10000
    FEEDBACK_HZ_MIN: ClassVar[int] = 1
    FEEDBACK_HZ_MAX: ClassVar[int] = 100
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('watchdog_ms', 'u16', 'int', 50, 2000, unit='ms'),
        FieldInfo('safe_state', 'SafeState', 'enum', 0, 2, enum=SafeState),
        FieldInfo('accel_limit_mm_s2', 'u16', 'int', 1, 65535, unit='mm/s^2'),
        FieldInfo('decel_limit_mm_s2', 'u16', 'int', 1, 65535, unit='mm/s^2'),
        FieldInfo('max_wheel_speed_mm_s', 'u16', 'int', 1, 20000, unit='mm/s'),
        FieldInfo('max_effort_permille', 'u16', 'int', 0, 1000, unit='0.1 %'),
        FieldInfo('encoder_cpr', 'u16', 'int', 1, 65535, unit='counts/rev'),
        FieldInfo('encoder_invert', 'u8', 'int', 0, 3),
        FieldInfo('motor_invert', 'u8', 'int', 0, 3),
        FieldInfo('wheel_diameter_um', 'u32', 'int', 1000, 1000000, unit='um'),
        FieldInfo('steering_center_cdeg', 'u16', 'int', 0, 18000, unit='0.01 deg'),
        FieldInfo('steering_min_cdeg', 'u16', 'int', 0, 18000, unit='0.01 deg'),
        FieldInfo('steering_max_cdeg', 'u16', 'int', 0, 18000, unit='0.01 deg'),
        FieldInfo('steering_step_cdeg', 'u16', 'int', 0, 9000, unit='0.01 deg'),
        FieldInfo('servo_min_us', 'u16', 'int', 400, 2600, unit='us'),
        FieldInfo('servo_max_us', 'u16', 'int', 400, 2600, unit='us'),
        FieldInfo('esc_min_us', 'u16', 'int', 800, 2200, unit='us'),
        FieldInfo('esc_neutral_us', 'u16', 'int', 800, 2200, unit='us'),
        FieldInfo('esc_max_us', 'u16', 'int', 800, 2200, unit='us'),
        FieldInfo('esc_arm_ms', 'u16', 'int', 0, 10000, unit='ms'),
        FieldInfo('feedback_hz', 'u8', 'int', 1, 100, unit='Hz'),
    )

    watchdog_ms: int
    """Default watchdog period (a HELLO may ask for another). [ms]"""
    safe_state: SafeState
    """Motor behaviour in FAILSAFE and when disarmed."""
    accel_limit_mm_s2: int
    """Largest setpoint increase per second. [mm/s^2]"""
    decel_limit_mm_s2: int
    """Largest setpoint decrease per second (also the RAMP_DOWN rate). [mm/s^2]"""
    max_wheel_speed_mm_s: int
    """Setpoints beyond this are refused with NACK(OUT_OF_RANGE); lowering it re-limits the running setpoint at the next tick. [mm/s]"""
    max_effort_permille: int
    """Motor effort limit (PID output clamp). [0.1 %]"""
    encoder_cpr: int
    """Encoder counts per wheel revolution after decoding and gearing. [counts/rev]"""
    encoder_invert: int
    """Bit i set: wheel i's encoder counts the other way."""
    motor_invert: int
    """Bit i set: wheel i's motor is wired the other way."""
    wheel_diameter_um: int
    """Wheel diameter, converts mm/s to counts/s. [um]"""
    steering_center_cdeg: int
    """Servo angle that steers straight. [0.01 deg]"""
    steering_min_cdeg: int
    """Smallest servo angle (full right). [0.01 deg]"""
    steering_max_cdeg: int
    """Largest servo angle (full left). [0.01 deg]"""
    steering_step_cdeg: int
    """Servo angles are quantised to centre + k * step (0: continuous). [0.01 deg]"""
    servo_min_us: int
    """Servo pulse width at 0 degrees. [us]"""
    servo_max_us: int
    """Servo pulse width at 180 degrees. [us]"""
    esc_min_us: int
    """ESC pulse for full reverse. [us]"""
    esc_neutral_us: int
    """ESC pulse for stop (sent during the boot calibration). [us]"""
    esc_max_us: int
    """ESC pulse for full forward. [us]"""
    esc_arm_ms: int
    """Arming sequence: neutral pulses held at boot before the ESC is driven. [ms]"""
    feedback_hz: int
    """Default stream feedback rate. [Hz]"""

    def pack(self) -> bytes:
        try:
            if 50 <= self.watchdog_ms <= 2000 and self.safe_state in _SAFESTATE and 1 <= self.accel_limit_mm_s2 <= 65535 and 1 <= self.decel_limit_mm_s2 <= 65535 and 1 <= self.max_wheel_speed_mm_s <= 20000 and 0 <= self.max_effort_permille <= 1000 and 1 <= self.encoder_cpr <= 65535 and 0 <= self.encoder_invert <= 3 and 0 <= self.motor_invert <= 3 and 1000 <= self.wheel_diameter_um <= 1000000 and 0 <= self.steering_center_cdeg <= 18000 and 0 <= self.steering_min_cdeg <= 18000 and 0 <= self.steering_max_cdeg <= 18000 and 0 <= self.steering_step_cdeg <= 9000 and 400 <= self.servo_min_us <= 2600 and 400 <= self.servo_max_us <= 2600 and 800 <= self.esc_min_us <= 2200 and 800 <= self.esc_neutral_us <= 2200 and 800 <= self.esc_max_us <= 2200 and 0 <= self.esc_arm_ms <= 10000 and 1 <= self.feedback_hz <= 100 and bool not in set(map(type, (self.watchdog_ms, self.safe_state, self.accel_limit_mm_s2, self.decel_limit_mm_s2, self.max_wheel_speed_mm_s, self.max_effort_permille, self.encoder_cpr, self.encoder_invert, self.motor_invert, self.wheel_diameter_um, self.steering_center_cdeg, self.steering_min_cdeg, self.steering_max_cdeg, self.steering_step_cdeg, self.servo_min_us, self.servo_max_us, self.esc_min_us, self.esc_neutral_us, self.esc_max_us, self.esc_arm_ms, self.feedback_hz,))):
                return _S_SET_CONFIG.pack(self.watchdog_ms, self.safe_state, self.accel_limit_mm_s2, self.decel_limit_mm_s2, self.max_wheel_speed_mm_s, self.max_effort_permille, self.encoder_cpr, self.encoder_invert, self.motor_invert, self.wheel_diameter_um, self.steering_center_cdeg, self.steering_min_cdeg, self.steering_max_cdeg, self.steering_step_cdeg, self.servo_min_us, self.servo_max_us, self.esc_min_us, self.esc_neutral_us, self.esc_max_us, self.esc_arm_ms, self.feedback_hz)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> SetConfig:
        if len(payload) != 40:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 40")
        v = _S_SET_CONFIG.unpack(payload)
        safe_state = _SAFESTATE.get(v[1])
        if safe_state is None:
            raise decode_error(cls, f"safe_state {v[1]} is not a value of SafeState")
        self = _new(cls)
        _SET_CONFIG_WATCHDOG_MS(self, v[0])
        _SET_CONFIG_SAFE_STATE(self, safe_state)
        _SET_CONFIG_ACCEL_LIMIT_MM_S2(self, v[2])
        _SET_CONFIG_DECEL_LIMIT_MM_S2(self, v[3])
        _SET_CONFIG_MAX_WHEEL_SPEED_MM_S(self, v[4])
        _SET_CONFIG_MAX_EFFORT_PERMILLE(self, v[5])
        _SET_CONFIG_ENCODER_CPR(self, v[6])
        _SET_CONFIG_ENCODER_INVERT(self, v[7])
        _SET_CONFIG_MOTOR_INVERT(self, v[8])
        _SET_CONFIG_WHEEL_DIAMETER_UM(self, v[9])
        _SET_CONFIG_STEERING_CENTER_CDEG(self, v[10])
        _SET_CONFIG_STEERING_MIN_CDEG(self, v[11])
        _SET_CONFIG_STEERING_MAX_CDEG(self, v[12])
        _SET_CONFIG_STEERING_STEP_CDEG(self, v[13])
        _SET_CONFIG_SERVO_MIN_US(self, v[14])
        _SET_CONFIG_SERVO_MAX_US(self, v[15])
        _SET_CONFIG_ESC_MIN_US(self, v[16])
        _SET_CONFIG_ESC_NEUTRAL_US(self, v[17])
        _SET_CONFIG_ESC_MAX_US(self, v[18])
        _SET_CONFIG_ESC_ARM_MS(self, v[19])
        _SET_CONFIG_FEEDBACK_HZ(self, v[20])
        return self


_SET_CONFIG_WATCHDOG_MS = slot_setter(SetConfig, "watchdog_ms")
_SET_CONFIG_SAFE_STATE = slot_setter(SetConfig, "safe_state")
_SET_CONFIG_ACCEL_LIMIT_MM_S2 = slot_setter(SetConfig, "accel_limit_mm_s2")
_SET_CONFIG_DECEL_LIMIT_MM_S2 = slot_setter(SetConfig, "decel_limit_mm_s2")
_SET_CONFIG_MAX_WHEEL_SPEED_MM_S = slot_setter(SetConfig, "max_wheel_speed_mm_s")
_SET_CONFIG_MAX_EFFORT_PERMILLE = slot_setter(SetConfig, "max_effort_permille")
_SET_CONFIG_ENCODER_CPR = slot_setter(SetConfig, "encoder_cpr")
_SET_CONFIG_ENCODER_INVERT = slot_setter(SetConfig, "encoder_invert")
_SET_CONFIG_MOTOR_INVERT = slot_setter(SetConfig, "motor_invert")
_SET_CONFIG_WHEEL_DIAMETER_UM = slot_setter(SetConfig, "wheel_diameter_um")
_SET_CONFIG_STEERING_CENTER_CDEG = slot_setter(SetConfig, "steering_center_cdeg")
_SET_CONFIG_STEERING_MIN_CDEG = slot_setter(SetConfig, "steering_min_cdeg")
_SET_CONFIG_STEERING_MAX_CDEG = slot_setter(SetConfig, "steering_max_cdeg")
_SET_CONFIG_STEERING_STEP_CDEG = slot_setter(SetConfig, "steering_step_cdeg")
_SET_CONFIG_SERVO_MIN_US = slot_setter(SetConfig, "servo_min_us")
_SET_CONFIG_SERVO_MAX_US = slot_setter(SetConfig, "servo_max_us")
_SET_CONFIG_ESC_MIN_US = slot_setter(SetConfig, "esc_min_us")
_SET_CONFIG_ESC_NEUTRAL_US = slot_setter(SetConfig, "esc_neutral_us")
_SET_CONFIG_ESC_MAX_US = slot_setter(SetConfig, "esc_max_us")
_SET_CONFIG_ESC_ARM_MS = slot_setter(SetConfig, "esc_arm_ms")
_SET_CONFIG_FEEDBACK_HZ = slot_setter(SetConfig, "feedback_hz")


@dataclass(frozen=True, slots=True)
class GetConfig(Message):
    """GET_CONFIG (0x15, host to mcu, reliable): Asks for the configuration; answered by CONFIG."""

    MSG_ID: ClassVar[int] = 0x15
    NAME: ClassVar[str] = "GET_CONFIG"
    CRC_EXTRA: ClassVar[int] = 0x59
    PAYLOAD_SIZE: ClassVar[int] = 0
    PAYLOAD_MAX: ClassVar[int] = 0
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = ()

    def pack(self) -> bytes:
        return b""

    @classmethod
    def unpack(cls, payload: bytes) -> GetConfig:
        if len(payload) != 0:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 0")
        return cls()


@dataclass(frozen=True, slots=True)
class SaveConfig(Message):
    """SAVE_CONFIG (0x16, host to mcu, reliable): Writes configuration and PID gains to EEPROM with a version and CRC; ACK after read-back verification."""

    MSG_ID: ClassVar[int] = 0x16
    NAME: ClassVar[str] = "SAVE_CONFIG"
    CRC_EXTRA: ClassVar[int] = 0x34
    PAYLOAD_SIZE: ClassVar[int] = 0
    PAYLOAD_MAX: ClassVar[int] = 0
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = ()

    def pack(self) -> bytes:
        return b""

    @classmethod
    def unpack(cls, payload: bytes) -> SaveConfig:
        if len(payload) != 0:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 0")
        return cls()


@dataclass(frozen=True, slots=True)
class ResetOdometry(Message):
    """RESET_ODOMETRY (0x17, host to mcu, reliable): Sets the cumulative encoder counts to zero."""

    MSG_ID: ClassVar[int] = 0x17
    NAME: ClassVar[str] = "RESET_ODOMETRY"
    CRC_EXTRA: ClassVar[int] = 0x85
    PAYLOAD_SIZE: ClassVar[int] = 0
    PAYLOAD_MAX: ClassVar[int] = 0
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = ()

    def pack(self) -> bytes:
        return b""

    @classmethod
    def unpack(cls, payload: bytes) -> ResetOdometry:
        if len(payload) != 0:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 0")
        return cls()


@dataclass(frozen=True, slots=True)
class GetLinkStats(Message):
    """GET_LINK_STATS (0x18, host to mcu, reliable): Asks for the firmware's link counters; answered by LINK_STATS."""

    MSG_ID: ClassVar[int] = 0x18
    NAME: ClassVar[str] = "GET_LINK_STATS"
    CRC_EXTRA: ClassVar[int] = 0x6C
    PAYLOAD_SIZE: ClassVar[int] = 0
    PAYLOAD_MAX: ClassVar[int] = 0
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = ()

    def pack(self) -> bytes:
        return b""

    @classmethod
    def unpack(cls, payload: bytes) -> GetLinkStats:
        if len(payload) != 0:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 0")
        return cls()


@dataclass(frozen=True, slots=True)
class SetLights(Message):
    """SET_LIGHTS (0x19, host to mcu, reliable): Chooses the turn signals' behaviour (capability TURN_SIGNALS, else NACK(UNSUPPORTED)), from the next control tick until another SET_LIGHTS, an accepted HELLO or a reset. The masks are kept in every mode (GET_LIGHTS reports them) but light lamps only in MANUAL."""

    MSG_ID: ClassVar[int] = 0x19
    NAME: ClassVar[str] = "SET_LIGHTS"
    CRC_EXTRA: ClassVar[int] = 0x46
    PAYLOAD_SIZE: ClassVar[int] = 4
    PAYLOAD_MAX: ClassVar[int] = 4
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    STEADY_MAX: ClassVar[int] = 15
    SLOW_MAX: ClassVar[int] = 15
    FAST_MAX: ClassVar[int] = 15
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('mode', 'LightsMode', 'enum', 0, 2, enum=LightsMode),
        FieldInfo('steady', 'u8', 'int', 0, 15),
        FieldInfo('slow', 'u8', 'int', 0, 15),
        FieldInfo('fast', 'u8', 'int', 0, 15),
    )

    mode: LightsMode
    """Who drives the lights."""
    steady: int
    """MANUAL: lamps lit steadily (Lights bits)."""
    slow: int
    """MANUAL: lamps blinking at 1.5 Hz, half on (Lights bits)."""
    fast: int
    """MANUAL: lamps blinking at 3 Hz, half on (Lights bits)."""

    def pack(self) -> bytes:
        try:
            if self.mode in _LIGHTSMODE and 0 <= self.steady <= 15 and 0 <= self.slow <= 15 and 0 <= self.fast <= 15 and bool not in set(map(type, (self.mode, self.steady, self.slow, self.fast,))):
                return _S_SET_LIGHTS.pack(self.mode, self.steady, self.slow, self.fast)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> SetLights:
        if len(payload) != 4:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 4")
        v = _S_SET_LIGHTS.unpack(payload)
        mode = _LIGHTSMODE.get(v[0])
        if mode is None:
            raise decode_error(cls, f"mode {v[0]} is not a value of LightsMode")
        self = _new(cls)
        _SET_LIGHTS_MODE(self, mode)
        _SET_LIGHTS_STEADY(self, v[1])
        _SET_LIGHTS_SLOW(self, v[2])
        _SET_LIGHTS_FAST(self, v[3])
        return self


_SET_LIGHTS_MODE = slot_setter(SetLights, "mode")
_SET_LIGHTS_STEADY = slot_setter(SetLights, "steady")
_SET_LIGHTS_SLOW = slot_setter(SetLights, "slow")
_SET_LIGHTS_FAST = slot_setter(SetLights, "fast")


@dataclass(frozen=True, slots=True)
class GetLights(Message):
    """GET_LIGHTS (0x1A, host to mcu, reliable): Asks for the turn signals' mode and the lamps lit; answered by LIGHTS_STATE (capability TURN_SIGNALS, else NACK(UNSUPPORTED))."""

    MSG_ID: ClassVar[int] = 0x1A
    NAME: ClassVar[str] = "GET_LIGHTS"
    CRC_EXTRA: ClassVar[int] = 0xF4
    PAYLOAD_SIZE: ClassVar[int] = 0
    PAYLOAD_MAX: ClassVar[int] = 0
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = ()

    def pack(self) -> bytes:
        return b""

    @classmethod
    def unpack(cls, payload: bytes) -> GetLights:
        if len(payload) != 0:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 0")
        return cls()


@dataclass(frozen=True, slots=True)
class SetWheelSpeeds(Message):
    """SET_WHEEL_SPEEDS (0x20, host to mcu, setpoint): Differential-drive setpoint: target speed of each wheel's rim. Stream mode: latest wins, applied at the next control tick. Lockstep: queued (LOCKSTEP_QUEUE), one applied per tick."""

    MSG_ID: ClassVar[int] = 0x20
    NAME: ClassVar[str] = "SET_WHEEL_SPEEDS"
    CRC_EXTRA: ClassVar[int] = 0xC9
    PAYLOAD_SIZE: ClassVar[int] = 4
    PAYLOAD_MAX: ClassVar[int] = 4
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.SETPOINT
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('left_mm_s', 'i16', 'int', -32768, 32767, unit='mm/s'),
        FieldInfo('right_mm_s', 'i16', 'int', -32768, 32767, unit='mm/s'),
    )

    left_mm_s: int
    """Left wheel target speed, positive forward. [mm/s]"""
    right_mm_s: int
    """Right wheel target speed, positive forward. [mm/s]"""

    def pack(self) -> bytes:
        try:
            if bool not in set(map(type, (self.left_mm_s, self.right_mm_s,))):
                return _S_SET_WHEEL_SPEEDS.pack(self.left_mm_s, self.right_mm_s)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> SetWheelSpeeds:
        if len(payload) != 4:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 4")
        v = _S_SET_WHEEL_SPEEDS.unpack(payload)
        self = _new(cls)
        _SET_WHEEL_SPEEDS_LEFT_MM_S(self, v[0])
        _SET_WHEEL_SPEEDS_RIGHT_MM_S(self, v[1])
        return self


_SET_WHEEL_SPEEDS_LEFT_MM_S = slot_setter(SetWheelSpeeds, "left_mm_s")
_SET_WHEEL_SPEEDS_RIGHT_MM_S = slot_setter(SetWheelSpeeds, "right_mm_s")


@dataclass(frozen=True, slots=True)
class SetAckermann(Message):
    """SET_ACKERMANN (0x21, host to mcu, setpoint): Ackermann setpoint: drive speed and front-wheel steering angle. Stream mode: latest wins, applied at the next control tick. Lockstep: queued (LOCKSTEP_QUEUE), one applied per tick."""

    MSG_ID: ClassVar[int] = 0x21
    NAME: ClassVar[str] = "SET_ACKERMANN"
    CRC_EXTRA: ClassVar[int] = 0x5D
    PAYLOAD_SIZE: ClassVar[int] = 4
    PAYLOAD_MAX: ClassVar[int] = 4
    DIRECTION: ClassVar[Direction] = Direction.HOST_TO_MCU
    DELIVERY: ClassVar[Delivery] = Delivery.SETPOINT
    STEERING_MRAD_MIN: ClassVar[int] = -1571
    STEERING_MRAD_MAX: ClassVar[int] = 1571
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('speed_mm_s', 'i16', 'int', -32768, 32767, unit='mm/s'),
        FieldInfo('steering_mrad', 'i16', 'int', -1571, 1571, unit='mrad'),
    )

    speed_mm_s: int
    """Target speed at the rear axle, positive forward. [mm/s]"""
    steering_mrad: int
    """Front-wheel angle, positive turns left. [mrad]"""

    def pack(self) -> bytes:
        try:
            if -1571 <= self.steering_mrad <= 1571 and bool not in set(map(type, (self.speed_mm_s, self.steering_mrad,))):
                return _S_SET_ACKERMANN.pack(self.speed_mm_s, self.steering_mrad)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> SetAckermann:
        if len(payload) != 4:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 4")
        v = _S_SET_ACKERMANN.unpack(payload)
        self = _new(cls)
        _SET_ACKERMANN_SPEED_MM_S(self, v[0])
        _SET_ACKERMANN_STEERING_MRAD(self, v[1])
        return self


_SET_ACKERMANN_SPEED_MM_S = slot_setter(SetAckermann, "speed_mm_s")
_SET_ACKERMANN_STEERING_MRAD = slot_setter(SetAckermann, "steering_mrad")


@dataclass(frozen=True, slots=True)
class Identity(Message):
    """IDENTITY (0x81, mcu to host, session): Boot announcement (sent once, unsolicited, after reset) and the answer to every HELLO."""

    MSG_ID: ClassVar[int] = 0x81
    NAME: ClassVar[str] = "IDENTITY"
    CRC_EXTRA: ClassVar[int] = 0x2B
    PAYLOAD_SIZE: ClassVar[int] = 25
    PAYLOAD_MAX: ClassVar[int] = 49
    DIRECTION: ClassVar[Direction] = Direction.MCU_TO_HOST
    DELIVERY: ClassVar[Delivery] = Delivery.SESSION
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('protocol_version', 'u8', 'int', 0, 255),
        FieldInfo('spec_hash', 'u32', 'int', 0, 4294967295),
        FieldInfo('firmware_version', 'u8[3]', 'int', 0, 255, count=3),
        FieldInfo('board', 'Board', 'enum', 0, 5, enum=Board),
        FieldInfo('capabilities', 'Capability', 'flags', 0, 255, enum=Capability),
        FieldInfo('boot_id', 'u32', 'int', 0, 4294967295),
        FieldInfo('uptime_ms', 'u32', 'int', 0, 4294967295, unit='ms'),
        FieldInfo('reason', 'IdentityReason', 'enum', 0, 2, enum=IdentityReason),
        FieldInfo('hello_seq', 'u8', 'int', 0, 255),
        FieldInfo('watchdog_ms', 'u16', 'int', 0, 65535, unit='ms'),
        FieldInfo('feedback_mode', 'FeedbackMode', 'enum', 0, 1, enum=FeedbackMode),
        FieldInfo('feedback_hz', 'u8', 'int', 0, 255, unit='Hz'),
        FieldInfo('robot_name', 'char[..24]', 'str', 0, 127, max_len=24),
    )

    protocol_version: int
    """Protocol version the firmware was built for."""
    spec_hash: int
    """Spec hash the firmware was built from."""
    firmware_version: tuple[int, int, int]
    """Firmware major, minor, patch."""
    board: Board
    """Board the firmware runs on."""
    capabilities: Capability
    """What this build can do."""
    boot_id: int
    """Random per boot; changes on every reset."""
    uptime_ms: int
    """Time since boot. [ms]"""
    reason: IdentityReason
    """Boot announcement, or the answer to a HELLO."""
    hello_seq: int
    """seq of the HELLO answered (0 for the boot announcement)."""
    watchdog_ms: int
    """Watchdog period granted for this session. [ms]"""
    feedback_mode: FeedbackMode
    """Feedback mode granted for this session."""
    feedback_hz: int
    """Stream rate granted for this session. [Hz]"""
    robot_name: str
    """Name of the firmware example (ASCII)."""

    def pack(self) -> bytes:
        try:
            if len(self.firmware_version) == 3 and self.board in _BOARD and self.capabilities in _CAPABILITY and self.reason in _IDENTITYREASON and self.feedback_mode in _FEEDBACKMODE and len(self.robot_name) <= 24 and bool not in set(map(type, (self.protocol_version, self.spec_hash, self.firmware_version[0], self.firmware_version[1], self.firmware_version[2], self.board, self.capabilities, self.boot_id, self.uptime_ms, self.reason, self.hello_seq, self.watchdog_ms, self.feedback_mode, self.feedback_hz,))):
                return _S_IDENTITY.pack(self.protocol_version, self.spec_hash, *self.firmware_version, self.board, self.capabilities, self.boot_id, self.uptime_ms, self.reason, self.hello_seq, self.watchdog_ms, self.feedback_mode, self.feedback_hz) + self.robot_name.encode("ascii")
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> Identity:
        if not 25 <= len(payload) <= 49:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 25..49")
        v = _S_IDENTITY.unpack(payload[:25])
        board = _BOARD.get(v[5])
        if board is None:
            raise decode_error(cls, f"board {v[5]} is not a value of Board")
        capabilities = _CAPABILITY.get(v[6])
        if capabilities is None:
            raise decode_error(cls, f"capabilities {v[6]} has bits outside Capability")
        reason = _IDENTITYREASON.get(v[9])
        if reason is None:
            raise decode_error(cls, f"reason {v[9]} is not a value of IdentityReason")
        feedback_mode = _FEEDBACKMODE.get(v[12])
        if feedback_mode is None:
            raise decode_error(cls, f"feedback_mode {v[12]} is not a value of FeedbackMode")
        tail = payload[25:]
        if not tail.isascii():
            raise decode_error(cls, "robot_name is not ASCII")
        self = _new(cls)
        _IDENTITY_PROTOCOL_VERSION(self, v[0])
        _IDENTITY_SPEC_HASH(self, v[1])
        _IDENTITY_FIRMWARE_VERSION(self, (v[2], v[3], v[4]))
        _IDENTITY_BOARD(self, board)
        _IDENTITY_CAPABILITIES(self, capabilities)
        _IDENTITY_BOOT_ID(self, v[7])
        _IDENTITY_UPTIME_MS(self, v[8])
        _IDENTITY_REASON(self, reason)
        _IDENTITY_HELLO_SEQ(self, v[10])
        _IDENTITY_WATCHDOG_MS(self, v[11])
        _IDENTITY_FEEDBACK_MODE(self, feedback_mode)
        _IDENTITY_FEEDBACK_HZ(self, v[13])
        _IDENTITY_ROBOT_NAME(self, tail.decode("ascii"))
        return self


_IDENTITY_PROTOCOL_VERSION = slot_setter(Identity, "protocol_version")
_IDENTITY_SPEC_HASH = slot_setter(Identity, "spec_hash")
_IDENTITY_FIRMWARE_VERSION = slot_setter(Identity, "firmware_version")
_IDENTITY_BOARD = slot_setter(Identity, "board")
_IDENTITY_CAPABILITIES = slot_setter(Identity, "capabilities")
_IDENTITY_BOOT_ID = slot_setter(Identity, "boot_id")
_IDENTITY_UPTIME_MS = slot_setter(Identity, "uptime_ms")
_IDENTITY_REASON = slot_setter(Identity, "reason")
_IDENTITY_HELLO_SEQ = slot_setter(Identity, "hello_seq")
_IDENTITY_WATCHDOG_MS = slot_setter(Identity, "watchdog_ms")
_IDENTITY_FEEDBACK_MODE = slot_setter(Identity, "feedback_mode")
_IDENTITY_FEEDBACK_HZ = slot_setter(Identity, "feedback_hz")
_IDENTITY_ROBOT_NAME = slot_setter(Identity, "robot_name")


@dataclass(frozen=True, slots=True)
class Pong(Message):
    """PONG (0x82, mcu to host, session): Answer to PING."""

    MSG_ID: ClassVar[int] = 0x82
    NAME: ClassVar[str] = "PONG"
    CRC_EXTRA: ClassVar[int] = 0xE6
    PAYLOAD_SIZE: ClassVar[int] = 8
    PAYLOAD_MAX: ClassVar[int] = 8
    DIRECTION: ClassVar[Direction] = Direction.MCU_TO_HOST
    DELIVERY: ClassVar[Delivery] = Delivery.SESSION
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('host_time_us', 'u32', 'int', 0, 4294967295, unit='us'),
        FieldInfo('mcu_time_us', 'u32', 'int', 0, 4294967295, unit='us'),
    )

    host_time_us: int
    """host_time_us of the PING. [us]"""
    mcu_time_us: int
    """MCU clock when the PING was processed. [us]"""

    def pack(self) -> bytes:
        try:
            if bool not in set(map(type, (self.host_time_us, self.mcu_time_us,))):
                return _S_PONG.pack(self.host_time_us, self.mcu_time_us)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> Pong:
        if len(payload) != 8:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 8")
        v = _S_PONG.unpack(payload)
        self = _new(cls)
        _PONG_HOST_TIME_US(self, v[0])
        _PONG_MCU_TIME_US(self, v[1])
        return self


_PONG_HOST_TIME_US = slot_setter(Pong, "host_time_us")
_PONG_MCU_TIME_US = slot_setter(Pong, "mcu_time_us")


@dataclass(frozen=True, slots=True)
class Ack(Message):
    """ACK (0x83, mcu to host, reliable): A reliable request was applied (or was a duplicate of one already applied)."""

    MSG_ID: ClassVar[int] = 0x83
    NAME: ClassVar[str] = "ACK"
    CRC_EXTRA: ClassVar[int] = 0x34
    PAYLOAD_SIZE: ClassVar[int] = 2
    PAYLOAD_MAX: ClassVar[int] = 2
    DIRECTION: ClassVar[Direction] = Direction.MCU_TO_HOST
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('req_id', 'u8', 'int', 0, 255),
        FieldInfo('req_seq', 'u8', 'int', 0, 255),
    )

    req_id: int
    """msg_id of the request."""
    req_seq: int
    """seq of the request."""

    def pack(self) -> bytes:
        try:
            if bool not in set(map(type, (self.req_id, self.req_seq,))):
                return _S_ACK.pack(self.req_id, self.req_seq)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> Ack:
        if len(payload) != 2:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 2")
        v = _S_ACK.unpack(payload)
        self = _new(cls)
        _ACK_REQ_ID(self, v[0])
        _ACK_REQ_SEQ(self, v[1])
        return self


_ACK_REQ_ID = slot_setter(Ack, "req_id")
_ACK_REQ_SEQ = slot_setter(Ack, "req_seq")


@dataclass(frozen=True, slots=True)
class Nack(Message):
    """NACK (0x84, mcu to host, reliable): A request was refused. Also answers setpoints that cannot be applied."""

    MSG_ID: ClassVar[int] = 0x84
    NAME: ClassVar[str] = "NACK"
    CRC_EXTRA: ClassVar[int] = 0xC6
    PAYLOAD_SIZE: ClassVar[int] = 4
    PAYLOAD_MAX: ClassVar[int] = 4
    DIRECTION: ClassVar[Direction] = Direction.MCU_TO_HOST
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('req_id', 'u8', 'int', 0, 255),
        FieldInfo('req_seq', 'u8', 'int', 0, 255),
        FieldInfo('reason', 'NackReason', 'enum', 1, 9, enum=NackReason),
        FieldInfo('detail', 'u8', 'int', 0, 255),
    )

    req_id: int
    """msg_id of the request."""
    req_seq: int
    """seq of the request."""
    reason: NackReason
    """Why."""
    detail: int
    """Reason-specific: field index, FailsafeReason, ..."""

    def pack(self) -> bytes:
        try:
            if self.reason in _NACKREASON and bool not in set(map(type, (self.req_id, self.req_seq, self.reason, self.detail,))):
                return _S_NACK.pack(self.req_id, self.req_seq, self.reason, self.detail)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> Nack:
        if len(payload) != 4:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 4")
        v = _S_NACK.unpack(payload)
        reason = _NACKREASON.get(v[2])
        if reason is None:
            raise decode_error(cls, f"reason {v[2]} is not a value of NackReason")
        self = _new(cls)
        _NACK_REQ_ID(self, v[0])
        _NACK_REQ_SEQ(self, v[1])
        _NACK_REASON(self, reason)
        _NACK_DETAIL(self, v[3])
        return self


_NACK_REQ_ID = slot_setter(Nack, "req_id")
_NACK_REQ_SEQ = slot_setter(Nack, "req_seq")
_NACK_REASON = slot_setter(Nack, "reason")
_NACK_DETAIL = slot_setter(Nack, "detail")


@dataclass(frozen=True, slots=True)
class Pid(Message):
    """PID (0x85, mcu to host, reliable): Answer to GET_PID."""

    MSG_ID: ClassVar[int] = 0x85
    NAME: ClassVar[str] = "PID"
    CRC_EXTRA: ClassVar[int] = 0x09
    PAYLOAD_SIZE: ClassVar[int] = 22
    PAYLOAD_MAX: ClassVar[int] = 22
    DIRECTION: ClassVar[Direction] = Direction.MCU_TO_HOST
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('req_seq', 'u8', 'int', 0, 255),
        FieldInfo('wheel', 'u8', 'int', 0, 255),
        FieldInfo('kp', 'f32', 'float', 0.0, 1000.0, unit='permille/(mm/s)'),
        FieldInfo('ki', 'f32', 'float', 0.0, 1000.0, unit='permille/mm'),
        FieldInfo('kd', 'f32', 'float', 0.0, 1000.0, unit='permille/(mm/s^2)'),
        FieldInfo('kf', 'f32', 'float', 0.0, 1000.0, unit='permille/(mm/s)'),
        FieldInfo('ks', 'f32', 'float', 0.0, 1000.0, unit='permille'),
    )

    req_seq: int
    """seq of the GET_PID."""
    wheel: int
    """Wheel index."""
    kp: float
    """Proportional gain. [permille/(mm/s)]"""
    ki: float
    """Integral gain (per second of error). [permille/mm]"""
    kd: float
    """Derivative gain, on the measurement. [permille/(mm/s^2)]"""
    kf: float
    """Feed-forward gain on the setpoint. [permille/(mm/s)]"""
    ks: float
    """Static-friction feed-forward: the effort that keeps the wheel turning at the lowest speeds, added with the setpoint's sign. [permille]"""

    def pack(self) -> bytes:
        try:
            if 0.0 <= self.kp <= 1000.0 and 0.0 <= self.ki <= 1000.0 and 0.0 <= self.kd <= 1000.0 and 0.0 <= self.kf <= 1000.0 and 0.0 <= self.ks <= 1000.0 and bool not in set(map(type, (self.req_seq, self.wheel, self.kp, self.ki, self.kd, self.kf, self.ks,))):
                return _S_PID.pack(self.req_seq, self.wheel, self.kp, self.ki, self.kd, self.kf, self.ks)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> Pid:
        if len(payload) != 22:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 22")
        v = _S_PID.unpack(payload)
        self = _new(cls)
        _PID_REQ_SEQ(self, v[0])
        _PID_WHEEL(self, v[1])
        _PID_KP(self, v[2])
        _PID_KI(self, v[3])
        _PID_KD(self, v[4])
        _PID_KF(self, v[5])
        _PID_KS(self, v[6])
        return self


_PID_REQ_SEQ = slot_setter(Pid, "req_seq")
_PID_WHEEL = slot_setter(Pid, "wheel")
_PID_KP = slot_setter(Pid, "kp")
_PID_KI = slot_setter(Pid, "ki")
_PID_KD = slot_setter(Pid, "kd")
_PID_KF = slot_setter(Pid, "kf")
_PID_KS = slot_setter(Pid, "ks")


@dataclass(frozen=True, slots=True)
class Config(Message):
    """CONFIG (0x86, mcu to host, reliable): Answer to GET_CONFIG."""

    MSG_ID: ClassVar[int] = 0x86
    NAME: ClassVar[str] = "CONFIG"
    CRC_EXTRA: ClassVar[int] = 0x18
    PAYLOAD_SIZE: ClassVar[int] = 41
    PAYLOAD_MAX: ClassVar[int] = 41
    DIRECTION: ClassVar[Direction] = Direction.MCU_TO_HOST
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    WATCHDOG_MS_MIN: ClassVar[int] = 50
    WATCHDOG_MS_MAX: ClassVar[int] = 2000
    ACCEL_LIMIT_MM_S2_MIN: ClassVar[int] = 1
    DECEL_LIMIT_MM_S2_MIN: ClassVar[int] = 1
    MAX_WHEEL_SPEED_MM_S_MIN: ClassVar[int] = 1
    MAX_WHEEL_SPEED_MM_S_MAX: ClassVar[int] = 20000
    MAX_EFFORT_PERMILLE_MAX: ClassVar[int] = 1000
    ENCODER_CPR_MIN: ClassVar[int] = 1
    ENCODER_INVERT_MAX: ClassVar[int] = 3
    MOTOR_INVERT_MAX: ClassVar[int] = 3
    WHEEL_DIAMETER_UM_MIN: ClassVar[int] = 1000
    WHEEL_DIAMETER_UM_MAX: ClassVar[int] = 1000000
    STEERING_CENTER_CDEG_MAX: ClassVar[int] = 18000
    STEERING_MIN_CDEG_MAX: ClassVar[int] = 18000
    STEERING_MAX_CDEG_MAX: ClassVar[int] = 18000
    STEERING_STEP_CDEG_MAX: ClassVar[int] = 9000
    SERVO_MIN_US_MIN: ClassVar[int] = 400
    SERVO_MIN_US_MAX: ClassVar[int] = 2600
    SERVO_MAX_US_MIN: ClassVar[int] = 400
    SERVO_MAX_US_MAX: ClassVar[int] = 2600
    ESC_MIN_US_MIN: ClassVar[int] = 800
    ESC_MIN_US_MAX: ClassVar[int] = 2200
    ESC_NEUTRAL_US_MIN: ClassVar[int] = 800
    ESC_NEUTRAL_US_MAX: ClassVar[int] = 2200
    ESC_MAX_US_MIN: ClassVar[int] = 800
    ESC_MAX_US_MAX: ClassVar[int] = 2200
    ESC_ARM_MS_MAX: ClassVar[int] = 10000
    FEEDBACK_HZ_MIN: ClassVar[int] = 1
    FEEDBACK_HZ_MAX: ClassVar[int] = 100
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('req_seq', 'u8', 'int', 0, 255),
        FieldInfo('watchdog_ms', 'u16', 'int', 50, 2000, unit='ms'),
        FieldInfo('safe_state', 'SafeState', 'enum', 0, 2, enum=SafeState),
        FieldInfo('accel_limit_mm_s2', 'u16', 'int', 1, 65535, unit='mm/s^2'),
        FieldInfo('decel_limit_mm_s2', 'u16', 'int', 1, 65535, unit='mm/s^2'),
        FieldInfo('max_wheel_speed_mm_s', 'u16', 'int', 1, 20000, unit='mm/s'),
        FieldInfo('max_effort_permille', 'u16', 'int', 0, 1000, unit='0.1 %'),
        FieldInfo('encoder_cpr', 'u16', 'int', 1, 65535, unit='counts/rev'),
        FieldInfo('encoder_invert', 'u8', 'int', 0, 3),
        FieldInfo('motor_invert', 'u8', 'int', 0, 3),
        FieldInfo('wheel_diameter_um', 'u32', 'int', 1000, 1000000, unit='um'),
        FieldInfo('steering_center_cdeg', 'u16', 'int', 0, 18000, unit='0.01 deg'),
        FieldInfo('steering_min_cdeg', 'u16', 'int', 0, 18000, unit='0.01 deg'),
        FieldInfo('steering_max_cdeg', 'u16', 'int', 0, 18000, unit='0.01 deg'),
        FieldInfo('steering_step_cdeg', 'u16', 'int', 0, 9000, unit='0.01 deg'),
        FieldInfo('servo_min_us', 'u16', 'int', 400, 2600, unit='us'),
        FieldInfo('servo_max_us', 'u16', 'int', 400, 2600, unit='us'),
        FieldInfo('esc_min_us', 'u16', 'int', 800, 2200, unit='us'),
        FieldInfo('esc_neutral_us', 'u16', 'int', 800, 2200, unit='us'),
        FieldInfo('esc_max_us', 'u16', 'int', 800, 2200, unit='us'),
        FieldInfo('esc_arm_ms', 'u16', 'int', 0, 10000, unit='ms'),
        FieldInfo('feedback_hz', 'u8', 'int', 1, 100, unit='Hz'),
    )

    req_seq: int
    """seq of the GET_CONFIG."""
    watchdog_ms: int
    """Default watchdog period (a HELLO may ask for another). [ms]"""
    safe_state: SafeState
    """Motor behaviour in FAILSAFE and when disarmed."""
    accel_limit_mm_s2: int
    """Largest setpoint increase per second. [mm/s^2]"""
    decel_limit_mm_s2: int
    """Largest setpoint decrease per second (also the RAMP_DOWN rate). [mm/s^2]"""
    max_wheel_speed_mm_s: int
    """Setpoints beyond this are refused with NACK(OUT_OF_RANGE); lowering it re-limits the running setpoint at the next tick. [mm/s]"""
    max_effort_permille: int
    """Motor effort limit (PID output clamp). [0.1 %]"""
    encoder_cpr: int
    """Encoder counts per wheel revolution after decoding and gearing. [counts/rev]"""
    encoder_invert: int
    """Bit i set: wheel i's encoder counts the other way."""
    motor_invert: int
    """Bit i set: wheel i's motor is wired the other way."""
    wheel_diameter_um: int
    """Wheel diameter, converts mm/s to counts/s. [um]"""
    steering_center_cdeg: int
    """Servo angle that steers straight. [0.01 deg]"""
    steering_min_cdeg: int
    """Smallest servo angle (full right). [0.01 deg]"""
    steering_max_cdeg: int
    """Largest servo angle (full left). [0.01 deg]"""
    steering_step_cdeg: int
    """Servo angles are quantised to centre + k * step (0: continuous). [0.01 deg]"""
    servo_min_us: int
    """Servo pulse width at 0 degrees. [us]"""
    servo_max_us: int
    """Servo pulse width at 180 degrees. [us]"""
    esc_min_us: int
    """ESC pulse for full reverse. [us]"""
    esc_neutral_us: int
    """ESC pulse for stop (sent during the boot calibration). [us]"""
    esc_max_us: int
    """ESC pulse for full forward. [us]"""
    esc_arm_ms: int
    """Arming sequence: neutral pulses held at boot before the ESC is driven. [ms]"""
    feedback_hz: int
    """Default stream feedback rate. [Hz]"""

    def pack(self) -> bytes:
        try:
            if 50 <= self.watchdog_ms <= 2000 and self.safe_state in _SAFESTATE and 1 <= self.accel_limit_mm_s2 <= 65535 and 1 <= self.decel_limit_mm_s2 <= 65535 and 1 <= self.max_wheel_speed_mm_s <= 20000 and 0 <= self.max_effort_permille <= 1000 and 1 <= self.encoder_cpr <= 65535 and 0 <= self.encoder_invert <= 3 and 0 <= self.motor_invert <= 3 and 1000 <= self.wheel_diameter_um <= 1000000 and 0 <= self.steering_center_cdeg <= 18000 and 0 <= self.steering_min_cdeg <= 18000 and 0 <= self.steering_max_cdeg <= 18000 and 0 <= self.steering_step_cdeg <= 9000 and 400 <= self.servo_min_us <= 2600 and 400 <= self.servo_max_us <= 2600 and 800 <= self.esc_min_us <= 2200 and 800 <= self.esc_neutral_us <= 2200 and 800 <= self.esc_max_us <= 2200 and 0 <= self.esc_arm_ms <= 10000 and 1 <= self.feedback_hz <= 100 and bool not in set(map(type, (self.req_seq, self.watchdog_ms, self.safe_state, self.accel_limit_mm_s2, self.decel_limit_mm_s2, self.max_wheel_speed_mm_s, self.max_effort_permille, self.encoder_cpr, self.encoder_invert, self.motor_invert, self.wheel_diameter_um, self.steering_center_cdeg, self.steering_min_cdeg, self.steering_max_cdeg, self.steering_step_cdeg, self.servo_min_us, self.servo_max_us, self.esc_min_us, self.esc_neutral_us, self.esc_max_us, self.esc_arm_ms, self.feedback_hz,))):
                return _S_CONFIG.pack(self.req_seq, self.watchdog_ms, self.safe_state, self.accel_limit_mm_s2, self.decel_limit_mm_s2, self.max_wheel_speed_mm_s, self.max_effort_permille, self.encoder_cpr, self.encoder_invert, self.motor_invert, self.wheel_diameter_um, self.steering_center_cdeg, self.steering_min_cdeg, self.steering_max_cdeg, self.steering_step_cdeg, self.servo_min_us, self.servo_max_us, self.esc_min_us, self.esc_neutral_us, self.esc_max_us, self.esc_arm_ms, self.feedback_hz)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> Config:
        if len(payload) != 41:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 41")
        v = _S_CONFIG.unpack(payload)
        safe_state = _SAFESTATE.get(v[2])
        if safe_state is None:
            raise decode_error(cls, f"safe_state {v[2]} is not a value of SafeState")
        self = _new(cls)
        _CONFIG_REQ_SEQ(self, v[0])
        _CONFIG_WATCHDOG_MS(self, v[1])
        _CONFIG_SAFE_STATE(self, safe_state)
        _CONFIG_ACCEL_LIMIT_MM_S2(self, v[3])
        _CONFIG_DECEL_LIMIT_MM_S2(self, v[4])
        _CONFIG_MAX_WHEEL_SPEED_MM_S(self, v[5])
        _CONFIG_MAX_EFFORT_PERMILLE(self, v[6])
        _CONFIG_ENCODER_CPR(self, v[7])
        _CONFIG_ENCODER_INVERT(self, v[8])
        _CONFIG_MOTOR_INVERT(self, v[9])
        _CONFIG_WHEEL_DIAMETER_UM(self, v[10])
        _CONFIG_STEERING_CENTER_CDEG(self, v[11])
        _CONFIG_STEERING_MIN_CDEG(self, v[12])
        _CONFIG_STEERING_MAX_CDEG(self, v[13])
        _CONFIG_STEERING_STEP_CDEG(self, v[14])
        _CONFIG_SERVO_MIN_US(self, v[15])
        _CONFIG_SERVO_MAX_US(self, v[16])
        _CONFIG_ESC_MIN_US(self, v[17])
        _CONFIG_ESC_NEUTRAL_US(self, v[18])
        _CONFIG_ESC_MAX_US(self, v[19])
        _CONFIG_ESC_ARM_MS(self, v[20])
        _CONFIG_FEEDBACK_HZ(self, v[21])
        return self


_CONFIG_REQ_SEQ = slot_setter(Config, "req_seq")
_CONFIG_WATCHDOG_MS = slot_setter(Config, "watchdog_ms")
_CONFIG_SAFE_STATE = slot_setter(Config, "safe_state")
_CONFIG_ACCEL_LIMIT_MM_S2 = slot_setter(Config, "accel_limit_mm_s2")
_CONFIG_DECEL_LIMIT_MM_S2 = slot_setter(Config, "decel_limit_mm_s2")
_CONFIG_MAX_WHEEL_SPEED_MM_S = slot_setter(Config, "max_wheel_speed_mm_s")
_CONFIG_MAX_EFFORT_PERMILLE = slot_setter(Config, "max_effort_permille")
_CONFIG_ENCODER_CPR = slot_setter(Config, "encoder_cpr")
_CONFIG_ENCODER_INVERT = slot_setter(Config, "encoder_invert")
_CONFIG_MOTOR_INVERT = slot_setter(Config, "motor_invert")
_CONFIG_WHEEL_DIAMETER_UM = slot_setter(Config, "wheel_diameter_um")
_CONFIG_STEERING_CENTER_CDEG = slot_setter(Config, "steering_center_cdeg")
_CONFIG_STEERING_MIN_CDEG = slot_setter(Config, "steering_min_cdeg")
_CONFIG_STEERING_MAX_CDEG = slot_setter(Config, "steering_max_cdeg")
_CONFIG_STEERING_STEP_CDEG = slot_setter(Config, "steering_step_cdeg")
_CONFIG_SERVO_MIN_US = slot_setter(Config, "servo_min_us")
_CONFIG_SERVO_MAX_US = slot_setter(Config, "servo_max_us")
_CONFIG_ESC_MIN_US = slot_setter(Config, "esc_min_us")
_CONFIG_ESC_NEUTRAL_US = slot_setter(Config, "esc_neutral_us")
_CONFIG_ESC_MAX_US = slot_setter(Config, "esc_max_us")
_CONFIG_ESC_ARM_MS = slot_setter(Config, "esc_arm_ms")
_CONFIG_FEEDBACK_HZ = slot_setter(Config, "feedback_hz")


@dataclass(frozen=True, slots=True)
class LinkStats(Message):
    """LINK_STATS (0x87, mcu to host, reliable): Answer to GET_LINK_STATS: the firmware's receive and transmit counters since boot."""

    MSG_ID: ClassVar[int] = 0x87
    NAME: ClassVar[str] = "LINK_STATS"
    CRC_EXTRA: ClassVar[int] = 0xA1
    PAYLOAD_SIZE: ClassVar[int] = 45
    PAYLOAD_MAX: ClassVar[int] = 45
    DIRECTION: ClassVar[Direction] = Direction.MCU_TO_HOST
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('req_seq', 'u8', 'int', 0, 255),
        FieldInfo('frames_ok', 'u32', 'int', 0, 4294967295),
        FieldInfo('crc_errors', 'u32', 'int', 0, 4294967295),
        FieldInfo('cobs_errors', 'u32', 'int', 0, 4294967295),
        FieldInfo('length_errors', 'u32', 'int', 0, 4294967295),
        FieldInfo('unknown_ids', 'u32', 'int', 0, 4294967295),
        FieldInfo('value_errors', 'u32', 'int', 0, 4294967295),
        FieldInfo('bytes_discarded', 'u32', 'int', 0, 4294967295),
        FieldInfo('seq_gaps', 'u32', 'int', 0, 4294967295),
        FieldInfo('duplicates', 'u32', 'int', 0, 4294967295),
        FieldInfo('frames_sent', 'u32', 'int', 0, 4294967295),
        FieldInfo('rx_overruns', 'u32', 'int', 0, 4294967295),
    )

    req_seq: int
    """seq of the GET_LINK_STATS."""
    frames_ok: int
    """Valid frames received."""
    crc_errors: int
    """Frames with a bad CRC."""
    cobs_errors: int
    """Chunks that were not valid COBS or were over-long."""
    length_errors: int
    """Frames whose length does not fit their msg_id."""
    unknown_ids: int
    """Frames with an unknown msg_id."""
    value_errors: int
    """Frames with a good CRC but a value the spec does not allow (e.g. an unknown enum value)."""
    bytes_discarded: int
    """Received bytes that were not part of a valid frame."""
    seq_gaps: int
    """Host frames missing according to seq."""
    duplicates: int
    """Reliable requests received again (answered, not re-applied)."""
    frames_sent: int
    """Frames sent."""
    rx_overruns: int
    """Bytes lost because the receive buffer was full."""

    def pack(self) -> bytes:
        try:
            if bool not in set(map(type, (self.req_seq, self.frames_ok, self.crc_errors, self.cobs_errors, self.length_errors, self.unknown_ids, self.value_errors, self.bytes_discarded, self.seq_gaps, self.duplicates, self.frames_sent, self.rx_overruns,))):
                return _S_LINK_STATS.pack(self.req_seq, self.frames_ok, self.crc_errors, self.cobs_errors, self.length_errors, self.unknown_ids, self.value_errors, self.bytes_discarded, self.seq_gaps, self.duplicates, self.frames_sent, self.rx_overruns)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> LinkStats:
        if len(payload) != 45:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 45")
        v = _S_LINK_STATS.unpack(payload)
        self = _new(cls)
        _LINK_STATS_REQ_SEQ(self, v[0])
        _LINK_STATS_FRAMES_OK(self, v[1])
        _LINK_STATS_CRC_ERRORS(self, v[2])
        _LINK_STATS_COBS_ERRORS(self, v[3])
        _LINK_STATS_LENGTH_ERRORS(self, v[4])
        _LINK_STATS_UNKNOWN_IDS(self, v[5])
        _LINK_STATS_VALUE_ERRORS(self, v[6])
        _LINK_STATS_BYTES_DISCARDED(self, v[7])
        _LINK_STATS_SEQ_GAPS(self, v[8])
        _LINK_STATS_DUPLICATES(self, v[9])
        _LINK_STATS_FRAMES_SENT(self, v[10])
        _LINK_STATS_RX_OVERRUNS(self, v[11])
        return self


_LINK_STATS_REQ_SEQ = slot_setter(LinkStats, "req_seq")
_LINK_STATS_FRAMES_OK = slot_setter(LinkStats, "frames_ok")
_LINK_STATS_CRC_ERRORS = slot_setter(LinkStats, "crc_errors")
_LINK_STATS_COBS_ERRORS = slot_setter(LinkStats, "cobs_errors")
_LINK_STATS_LENGTH_ERRORS = slot_setter(LinkStats, "length_errors")
_LINK_STATS_UNKNOWN_IDS = slot_setter(LinkStats, "unknown_ids")
_LINK_STATS_VALUE_ERRORS = slot_setter(LinkStats, "value_errors")
_LINK_STATS_BYTES_DISCARDED = slot_setter(LinkStats, "bytes_discarded")
_LINK_STATS_SEQ_GAPS = slot_setter(LinkStats, "seq_gaps")
_LINK_STATS_DUPLICATES = slot_setter(LinkStats, "duplicates")
_LINK_STATS_FRAMES_SENT = slot_setter(LinkStats, "frames_sent")
_LINK_STATS_RX_OVERRUNS = slot_setter(LinkStats, "rx_overruns")


@dataclass(frozen=True, slots=True)
class LightsState(Message):
    """LIGHTS_STATE (0x88, mcu to host, reliable): Answer to GET_LIGHTS: the mode in force, its masks, and the lamps lit by the last control tick."""

    MSG_ID: ClassVar[int] = 0x88
    NAME: ClassVar[str] = "LIGHTS_STATE"
    CRC_EXTRA: ClassVar[int] = 0xD9
    PAYLOAD_SIZE: ClassVar[int] = 6
    PAYLOAD_MAX: ClassVar[int] = 6
    DIRECTION: ClassVar[Direction] = Direction.MCU_TO_HOST
    DELIVERY: ClassVar[Delivery] = Delivery.RELIABLE
    STEADY_MAX: ClassVar[int] = 15
    SLOW_MAX: ClassVar[int] = 15
    FAST_MAX: ClassVar[int] = 15
    LIT_MAX: ClassVar[int] = 15
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('req_seq', 'u8', 'int', 0, 255),
        FieldInfo('mode', 'LightsMode', 'enum', 0, 2, enum=LightsMode),
        FieldInfo('steady', 'u8', 'int', 0, 15),
        FieldInfo('slow', 'u8', 'int', 0, 15),
        FieldInfo('fast', 'u8', 'int', 0, 15),
        FieldInfo('lit', 'u8', 'int', 0, 15),
    )

    req_seq: int
    """seq of the GET_LIGHTS."""
    mode: LightsMode
    """Who drives the lights."""
    steady: int
    """MANUAL: lamps lit steadily (Lights bits)."""
    slow: int
    """MANUAL: lamps blinking at 1.5 Hz, half on (Lights bits)."""
    fast: int
    """MANUAL: lamps blinking at 3 Hz, half on (Lights bits)."""
    lit: int
    """Lamps lit at the last control tick (Lights bits)."""

    def pack(self) -> bytes:
        try:
            if self.mode in _LIGHTSMODE and 0 <= self.steady <= 15 and 0 <= self.slow <= 15 and 0 <= self.fast <= 15 and 0 <= self.lit <= 15 and bool not in set(map(type, (self.req_seq, self.mode, self.steady, self.slow, self.fast, self.lit,))):
                return _S_LIGHTS_STATE.pack(self.req_seq, self.mode, self.steady, self.slow, self.fast, self.lit)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> LightsState:
        if len(payload) != 6:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 6")
        v = _S_LIGHTS_STATE.unpack(payload)
        mode = _LIGHTSMODE.get(v[1])
        if mode is None:
            raise decode_error(cls, f"mode {v[1]} is not a value of LightsMode")
        self = _new(cls)
        _LIGHTS_STATE_REQ_SEQ(self, v[0])
        _LIGHTS_STATE_MODE(self, mode)
        _LIGHTS_STATE_STEADY(self, v[2])
        _LIGHTS_STATE_SLOW(self, v[3])
        _LIGHTS_STATE_FAST(self, v[4])
        _LIGHTS_STATE_LIT(self, v[5])
        return self


_LIGHTS_STATE_REQ_SEQ = slot_setter(LightsState, "req_seq")
_LIGHTS_STATE_MODE = slot_setter(LightsState, "mode")
_LIGHTS_STATE_STEADY = slot_setter(LightsState, "steady")
_LIGHTS_STATE_SLOW = slot_setter(LightsState, "slow")
_LIGHTS_STATE_FAST = slot_setter(LightsState, "fast")
_LIGHTS_STATE_LIT = slot_setter(LightsState, "lit")


@dataclass(frozen=True, slots=True)
class Feedback(Message):
    """FEEDBACK (0x90, mcu to host, telemetry): Robot state at one control tick. Streamed every round(CONTROL_RATE_HZ / feedback_hz) ticks: before any HELLO at the config's rate; in a stream session at the session's feedback_hz; in a lockstep session while it is not ARMED (DISARMED, FAILSAFE) as in stream mode, the first in the first tick out of ARMED. In a lockstep session while ARMED: exactly one in each tick that applied a setpoint, none in any other."""

    MSG_ID: ClassVar[int] = 0x90
    NAME: ClassVar[str] = "FEEDBACK"
    CRC_EXTRA: ClassVar[int] = 0x3F
    PAYLOAD_SIZE: ClassVar[int] = 33
    PAYLOAD_MAX: ClassVar[int] = 33
    DIRECTION: ClassVar[Direction] = Direction.MCU_TO_HOST
    DELIVERY: ClassVar[Delivery] = Delivery.TELEMETRY
    EFFORT_PERMILLE_MIN: ClassVar[int] = -1000
    EFFORT_PERMILLE_MAX: ClassVar[int] = 1000
    STEERING_MRAD_MIN: ClassVar[int] = -1571
    STEERING_MRAD_MAX: ClassVar[int] = 1571
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('boot_id', 'u32', 'int', 0, 4294967295),
        FieldInfo('mcu_time_us', 'u32', 'int', 0, 4294967295, unit='us'),
        FieldInfo('tick', 'u16', 'int', 0, 65535),
        FieldInfo('ack_seq', 'u8', 'int', 0, 255),
        FieldInfo('ack_tick', 'u16', 'int', 0, 65535),
        FieldInfo('status', 'Status', 'flags', 0, 127, enum=Status),
        FieldInfo('failsafe_reason', 'FailsafeReason', 'enum', 0, 4, enum=FailsafeReason),
        FieldInfo('encoder_counts', 'i32[2]', 'int', -2147483648, 2147483647, count=2),
        FieldInfo('wheel_speed_mm_s', 'i16[2]', 'int', -32768, 32767, unit='mm/s', count=2),
        FieldInfo('effort_permille', 'i16[2]', 'int', -1000, 1000, unit='0.1 %', count=2),
        FieldInfo('steering_mrad', 'i16', 'int', -1571, 1571, unit='mrad'),
    )

    boot_id: int
    """boot_id of the running boot: a change means the board was reset."""
    mcu_time_us: int
    """MCU clock at the tick (wraps every 71.6 min; the host unwraps it). [us]"""
    tick: int
    """Control tick counter (wraps; the host unwraps it)."""
    ack_seq: int
    """seq of the last setpoint applied."""
    ack_tick: int
    """tick at which that setpoint was applied."""
    status: Status
    """Status bits."""
    failsafe_reason: FailsafeReason
    """Latched failsafe reason (NONE when not in failsafe)."""
    encoder_counts: tuple[int, int]
    """Cumulative encoder counts per wheel, captured atomically (wraps at 2^32)."""
    wheel_speed_mm_s: tuple[int, int]
    """Measured wheel speeds. [mm/s]"""
    effort_permille: tuple[int, int]
    """Motor efforts applied (negative: reverse). [0.1 %]"""
    steering_mrad: int
    """Front-wheel angle commanded to the servo (0 without steering). [mrad]"""

    def pack(self) -> bytes:
        try:
            if self.status in _STATUS and self.failsafe_reason in _FAILSAFEREASON and len(self.encoder_counts) == 2 and len(self.wheel_speed_mm_s) == 2 and len(self.effort_permille) == 2 and -1000 <= self.effort_permille[0] <= 1000 and -1000 <= self.effort_permille[1] <= 1000 and -1571 <= self.steering_mrad <= 1571 and bool not in set(map(type, (self.boot_id, self.mcu_time_us, self.tick, self.ack_seq, self.ack_tick, self.status, self.failsafe_reason, self.encoder_counts[0], self.encoder_counts[1], self.wheel_speed_mm_s[0], self.wheel_speed_mm_s[1], self.effort_permille[0], self.effort_permille[1], self.steering_mrad,))):
                return _S_FEEDBACK.pack(self.boot_id, self.mcu_time_us, self.tick, self.ack_seq, self.ack_tick, self.status, self.failsafe_reason, *self.encoder_counts, *self.wheel_speed_mm_s, *self.effort_permille, self.steering_mrad)
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> Feedback:
        if len(payload) != 33:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 33")
        v = _S_FEEDBACK.unpack(payload)
        status = _STATUS.get(v[5])
        if status is None:
            raise decode_error(cls, f"status {v[5]} has bits outside Status")
        failsafe_reason = _FAILSAFEREASON.get(v[6])
        if failsafe_reason is None:
            raise decode_error(cls, f"failsafe_reason {v[6]} is not a value of FailsafeReason")
        self = _new(cls)
        _FEEDBACK_BOOT_ID(self, v[0])
        _FEEDBACK_MCU_TIME_US(self, v[1])
        _FEEDBACK_TICK(self, v[2])
        _FEEDBACK_ACK_SEQ(self, v[3])
        _FEEDBACK_ACK_TICK(self, v[4])
        _FEEDBACK_STATUS(self, status)
        _FEEDBACK_FAILSAFE_REASON(self, failsafe_reason)
        _FEEDBACK_ENCODER_COUNTS(self, (v[7], v[8]))
        _FEEDBACK_WHEEL_SPEED_MM_S(self, (v[9], v[10]))
        _FEEDBACK_EFFORT_PERMILLE(self, (v[11], v[12]))
        _FEEDBACK_STEERING_MRAD(self, v[13])
        return self


_FEEDBACK_BOOT_ID = slot_setter(Feedback, "boot_id")
_FEEDBACK_MCU_TIME_US = slot_setter(Feedback, "mcu_time_us")
_FEEDBACK_TICK = slot_setter(Feedback, "tick")
_FEEDBACK_ACK_SEQ = slot_setter(Feedback, "ack_seq")
_FEEDBACK_ACK_TICK = slot_setter(Feedback, "ack_tick")
_FEEDBACK_STATUS = slot_setter(Feedback, "status")
_FEEDBACK_FAILSAFE_REASON = slot_setter(Feedback, "failsafe_reason")
_FEEDBACK_ENCODER_COUNTS = slot_setter(Feedback, "encoder_counts")
_FEEDBACK_WHEEL_SPEED_MM_S = slot_setter(Feedback, "wheel_speed_mm_s")
_FEEDBACK_EFFORT_PERMILLE = slot_setter(Feedback, "effort_permille")
_FEEDBACK_STEERING_MRAD = slot_setter(Feedback, "steering_mrad")


@dataclass(frozen=True, slots=True)
class Log(Message):
    """LOG (0x91, mcu to host, telemetry): A short text from the firmware. The firmware never prints text on the port; this is its only text channel."""

    MSG_ID: ClassVar[int] = 0x91
    NAME: ClassVar[str] = "LOG"
    CRC_EXTRA: ClassVar[int] = 0x13
    PAYLOAD_SIZE: ClassVar[int] = 1
    PAYLOAD_MAX: ClassVar[int] = 61
    DIRECTION: ClassVar[Direction] = Direction.MCU_TO_HOST
    DELIVERY: ClassVar[Delivery] = Delivery.TELEMETRY
    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (
        FieldInfo('level', 'LogLevel', 'enum', 0, 3, enum=LogLevel),
        FieldInfo('text', 'char[..60]', 'str', 0, 127, max_len=60),
    )

    level: LogLevel
    """Severity."""
    text: str
    """ASCII text."""

    def pack(self) -> bytes:
        try:
            if self.level in _LOGLEVEL and len(self.text) <= 60 and bool not in set(map(type, (self.level,))):
                return _S_LOG.pack(self.level) + self.text.encode("ascii")
        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):
            pass
        raise first_invalid(self)

    @classmethod
    def unpack(cls, payload: bytes) -> Log:
        if not 1 <= len(payload) <= 61:
            raise decode_error(cls, f"payload is {len(payload)} bytes, expected 1..61")
        v = _S_LOG.unpack(payload[:1])
        level = _LOGLEVEL.get(v[0])
        if level is None:
            raise decode_error(cls, f"level {v[0]} is not a value of LogLevel")
        tail = payload[1:]
        if not tail.isascii():
            raise decode_error(cls, "text is not ASCII")
        self = _new(cls)
        _LOG_LEVEL(self, level)
        _LOG_TEXT(self, tail.decode("ascii"))
        return self


_LOG_LEVEL = slot_setter(Log, "level")
_LOG_TEXT = slot_setter(Log, "text")


ALL_MESSAGES: tuple[type[Message], ...] = (
    Hello,
    Ping,
    Arm,
    Disarm,
    SetPid,
    GetPid,
    SetConfig,
    GetConfig,
    SaveConfig,
    ResetOdometry,
    GetLinkStats,
    SetLights,
    GetLights,
    SetWheelSpeeds,
    SetAckermann,
    Identity,
    Pong,
    Ack,
    Nack,
    Pid,
    Config,
    LinkStats,
    LightsState,
    Feedback,
    Log,
)
"""Every message class, in spec order."""

BY_ID: dict[int, type[Message]] = {m.MSG_ID: m for m in ALL_MESSAGES}
"""Message class by msg_id."""

__all__ = [
    "ALL_MESSAGES",
    "BY_ID",
    "Hello",
    "Ping",
    "Arm",
    "Disarm",
    "SetPid",
    "GetPid",
    "SetConfig",
    "GetConfig",
    "SaveConfig",
    "ResetOdometry",
    "GetLinkStats",
    "SetLights",
    "GetLights",
    "SetWheelSpeeds",
    "SetAckermann",
    "Identity",
    "Pong",
    "Ack",
    "Nack",
    "Pid",
    "Config",
    "LinkStats",
    "LightsState",
    "Feedback",
    "Log",
]
