# DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
# spec hash: 0xBDF31659
"""Enumerations and bit flags."""

import enum


class Board(enum.IntEnum):
    """Which board (or model of one) runs the firmware."""

    UNKNOWN = 0
    """Not reported."""
    NATIVE = 1
    """The firmware core built for the host (tests)."""
    EMULATOR = 2
    """The Python reference emulator."""
    UNO = 3
    """Arduino Uno (ATmega328P)."""
    MEGA2560 = 4
    """Arduino Mega 2560 (ATmega2560)."""
    PICO = 5
    """Raspberry Pi Pico (RP2040)."""


class Capability(enum.IntFlag):
    """What this firmware build can do."""

    DIFF_DRIVE = 0x1
    """Two independently driven wheels (SET_WHEEL_SPEEDS)."""
    ACKERMANN = 0x2
    """One drive motor plus a steering servo (SET_ACKERMANN)."""
    ENCODERS = 0x4
    """Quadrature encoders, closed-loop speed control."""
    STEERING_SERVO = 0x8
    """A steering servo."""
    ESC = 0x10
    """Drive motor behind an RC electronic speed controller."""
    EEPROM = 0x20
    """SAVE_CONFIG persists the configuration."""
    TURN_SIGNALS = 0x40
    """Four turn-signal LEDs: driven by motion state, or as SET_LIGHTS chooses (GET_LIGHTS reports them)."""
    LOCKSTEP = 0x80
    """Lockstep feedback mode."""


class FeedbackMode(enum.IntEnum):
    """How FEEDBACK is scheduled."""

    STREAM = 0
    """FEEDBACK at a fixed rate; setpoints whenever the host likes."""
    LOCKSTEP = 1
    """While ARMED, exactly one FEEDBACK answers each applied setpoint (none without one); while the session is open but not ARMED, FEEDBACK streams at feedback_hz as in STREAM, the first in the first tick out of ARMED."""


class SafeState(enum.IntEnum):
    """What the motors do in FAILSAFE and when disarmed."""

    COAST = 0
    """Drivers off, wheels free."""
    BRAKE = 1
    """Short-circuit brake (ESC: neutral)."""
    RAMP_DOWN = 2
    """Ramp wheel speed setpoints to zero at decel_limit_mm_s2, then coast."""


class FailsafeReason(enum.IntEnum):
    """Why the firmware entered FAILSAFE (latched until the next ARM)."""

    NONE = 0
    """Not in failsafe."""
    COMM_TIMEOUT = 1
    """No valid host frame for the watchdog period."""
    ENCODER_FAULT = 2
    """Effort applied but the encoder did not move: a blocked wheel, or an unplugged encoder."""
    BAD_CONFIG = 3
    """The configuration is inconsistent."""
    LOW_VOLTAGE = 4
    """Supply voltage below the safe limit."""


class NackReason(enum.IntEnum):
    """Why a request was refused."""

    NOT_ARMED = 1
    """Setpoint while disarmed."""
    FAILSAFE = 2
    """Setpoint while in FAILSAFE; `detail` holds the FailsafeReason."""
    NO_SESSION = 3
    """Request needs a session: send HELLO first."""
    BOOT_ID_MISMATCH = 4
    """ARM named another boot_id: the board was reset."""
    OUT_OF_RANGE = 5
    """A field is out of range; `detail` is the field's index in the message."""
    UNSUPPORTED = 6
    """This build cannot do that (e.g. SET_ACKERMANN on a diff-drive)."""
    EEPROM_ERROR = 7
    """Writing or verifying the EEPROM failed."""
    INVALID_CONFIG = 8
    """Fields are in range but inconsistent; `detail` is the first bad field's index."""
    ARMED = 9
    """Not allowed while armed (SAVE_CONFIG: EEPROM writes would stall the control loop)."""


class Status(enum.IntFlag):
    """Status bits carried in every FEEDBACK."""

    SESSION = 0x1
    """A HELLO was accepted: the session is open."""
    ARMED = 0x2
    """Motors enabled, setpoints applied."""
    FAILSAFE = 0x4
    """FAILSAFE latched; see failsafe_reason."""
    SATURATED = 0x8
    """A motor effort hit its limit this tick."""
    ENCODER_FAULT = 0x10
    """A wheel did not turn under effort: blocked, or its encoder unplugged."""
    CONFIG_DEFAULTS = 0x20
    """EEPROM config was missing or corrupt; defaults in use."""
    LOCKSTEP = 0x40
    """The session runs in lockstep mode."""


class IdentityReason(enum.IntEnum):
    """Why an IDENTITY was sent."""

    BOOT = 0
    """Unsolicited boot announcement."""
    HELLO_ACCEPTED = 1
    """Answer to a compatible HELLO: the session is open."""
    HELLO_REJECTED = 2
    """Answer to a HELLO with another protocol version or spec hash: no session."""


class LightsMode(enum.IntEnum):
    """Who drives the turn signals (SET_LIGHTS). Whatever the mode, FAILSAFE shows all four blinking fast; a reset and an accepted HELLO bring back the robot's power-up mode."""

    AUTO = 0
    """From the motion state: the pair on the side of a turn, all four spinning in place, front and rear alternating out of ARMED."""
    OFF = 1
    """All four dark."""
    MANUAL = 2
    """Each lamp as the steady, slow and fast masks say: lit when it is in steady, or in slow during the on half of the 1.5 Hz blink, or in fast during the on half of the 3 Hz blink."""


class LogLevel(enum.IntEnum):
    """Severity of a LOG frame."""

    DEBUG = 0
    """Developer detail."""
    INFO = 1
    """Normal event."""
    WARN = 2
    """Something the user should look at."""
    ERROR = 3
    """Something failed."""


__all__ = ["Board", "Capability", "FeedbackMode", "SafeState", "FailsafeReason", "NackReason", "Status", "IdentityReason", "LightsMode", "LogLevel"]
