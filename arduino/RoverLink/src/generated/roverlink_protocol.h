// DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
// spec hash: 0xBDF31659
// RoverLink protocol: constants, enums, message structs (packed wire images) and their checks,
// pack/unpack, dispatch, state table.
#ifndef ROVERLINK_GENERATED_PROTOCOL_H
#define ROVERLINK_GENERATED_PROTOCOL_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

// The runtime's copy_payload() and f32 order keys, ROVERLINK_PACKED and ROVERLINK_PROGMEM.
#include "../wire/layout.h"

// The codec in src/codec/ refuses to compile against another API version (see codec.h).
#define ROVERLINK_GENERATED_API_VERSION 4

namespace roverlink {
namespace proto {

static const uint8_t PROTOCOL_VERSION = 2;
static const uint32_t SPEC_HASH = 0xBDF31659UL;
static const uint8_t MAX_PAYLOAD = 64;
static const uint8_t MAX_BODY = 68;  // msg_id + seq + payload + crc
static const uint8_t MAX_FRAME = 70;  // COBS-encoded body + delimiter

// Watchdog period used when HELLO asks for 0 and the stored config has none.
static const uint16_t WATCHDOG_DEFAULT_MS = 250;
// Shortest watchdog period the firmware grants (five control ticks).
static const uint16_t WATCHDOG_MIN_MS = 50;
// Longest watchdog period the firmware grants.
static const uint16_t WATCHDOG_MAX_MS = 2000;
// Control loop rate: PID, limits, watchdog check and stream feedback scheduling run once per tick.
static const uint16_t CONTROL_RATE_HZ = 100;
// Setpoints an ARMED lockstep session holds for its next ticks, applied one per tick in arrival order; one arriving to a full queue replaces the newest. A host may so stay a tick ahead, and be late by most of two ticks without a tick going unanswered. Stream mode holds one (latest wins).
static const uint8_t LOCKSTEP_QUEUE = 2;
// Stream feedback rate when HELLO asks for 0.
static const uint8_t FEEDBACK_HZ_DEFAULT = 50;
// Highest stream feedback rate (one FEEDBACK per control tick).
static const uint8_t FEEDBACK_HZ_MAX = 100;
// How often the host repeats HELLO until IDENTITY arrives.
static const uint16_t HELLO_INTERVAL_MS = 100;
// Wheel channels carried in setpoints and feedback; a single-motor robot uses channel 0.
static const uint8_t WHEEL_COUNT = 2;
// SET_PID wheel index that addresses every wheel at once.
static const uint8_t PID_ALL_WHEELS = 255;

// Which board (or model of one) runs the firmware.
enum class Board : uint8_t {
    UNKNOWN = 0,  // Not reported.
    NATIVE = 1,  // The firmware core built for the host (tests).
    EMULATOR = 2,  // The Python reference emulator.
    UNO = 3,  // Arduino Uno (ATmega328P).
    MEGA2560 = 4,  // Arduino Mega 2560 (ATmega2560).
    PICO = 5,  // Raspberry Pi Pico (RP2040).
};
inline bool is_valid_Board(uint8_t value) {
    return value <= 5;
}

// What this firmware build can do.
struct Capability {
    enum : uint16_t {
        DIFF_DRIVE = 0x1,  // Two independently driven wheels (SET_WHEEL_SPEEDS).
        ACKERMANN = 0x2,  // One drive motor plus a steering servo (SET_ACKERMANN).
        ENCODERS = 0x4,  // Quadrature encoders, closed-loop speed control.
        STEERING_SERVO = 0x8,  // A steering servo.
        ESC = 0x10,  // Drive motor behind an RC electronic speed controller.
        EEPROM = 0x20,  // SAVE_CONFIG persists the configuration.
        TURN_SIGNALS = 0x40,  // Four turn-signal LEDs: driven by motion state, or as SET_LIGHTS chooses (GET_LIGHTS reports them).
        LOCKSTEP = 0x80,  // Lockstep feedback mode.
    };
    static const uint16_t MASK = 0xFF;
};

// How FEEDBACK is scheduled.
enum class FeedbackMode : uint8_t {
    STREAM = 0,  // FEEDBACK at a fixed rate; setpoints whenever the host likes.
    LOCKSTEP = 1,  // While ARMED, exactly one FEEDBACK answers each applied setpoint (none without one); while the session is open but not ARMED, FEEDBACK streams at feedback_hz as in STREAM, the first in the first tick out of ARMED.
};
inline bool is_valid_FeedbackMode(uint8_t value) {
    return value <= 1;
}

// What the motors do in FAILSAFE and when disarmed.
enum class SafeState : uint8_t {
    COAST = 0,  // Drivers off, wheels free.
    BRAKE = 1,  // Short-circuit brake (ESC: neutral).
    RAMP_DOWN = 2,  // Ramp wheel speed setpoints to zero at decel_limit_mm_s2, then coast.
};
inline bool is_valid_SafeState(uint8_t value) {
    return value <= 2;
}

// Why the firmware entered FAILSAFE (latched until the next ARM).
enum class FailsafeReason : uint8_t {
    NONE = 0,  // Not in failsafe.
    COMM_TIMEOUT = 1,  // No valid host frame for the watchdog period.
    ENCODER_FAULT = 2,  // Effort applied but the encoder did not move: a blocked wheel, or an unplugged encoder.
    BAD_CONFIG = 3,  // The configuration is inconsistent.
    LOW_VOLTAGE = 4,  // Supply voltage below the safe limit.
};
inline bool is_valid_FailsafeReason(uint8_t value) {
    return value <= 4;
}

// Why a request was refused.
enum class NackReason : uint8_t {
    NOT_ARMED = 1,  // Setpoint while disarmed.
    FAILSAFE = 2,  // Setpoint while in FAILSAFE; `detail` holds the FailsafeReason.
    NO_SESSION = 3,  // Request needs a session: send HELLO first.
    BOOT_ID_MISMATCH = 4,  // ARM named another boot_id: the board was reset.
    OUT_OF_RANGE = 5,  // A field is out of range; `detail` is the field's index in the message.
    UNSUPPORTED = 6,  // This build cannot do that (e.g. SET_ACKERMANN on a diff-drive).
    EEPROM_ERROR = 7,  // Writing or verifying the EEPROM failed.
    INVALID_CONFIG = 8,  // Fields are in range but inconsistent; `detail` is the first bad field's index.
    ARMED = 9,  // Not allowed while armed (SAVE_CONFIG: EEPROM writes would stall the control loop).
};
inline bool is_valid_NackReason(uint8_t value) {
    return value >= 1 && value <= 9;
}

// Status bits carried in every FEEDBACK.
struct Status {
    enum : uint8_t {
        SESSION = 0x1,  // A HELLO was accepted: the session is open.
        ARMED = 0x2,  // Motors enabled, setpoints applied.
        FAILSAFE = 0x4,  // FAILSAFE latched; see failsafe_reason.
        SATURATED = 0x8,  // A motor effort hit its limit this tick.
        ENCODER_FAULT = 0x10,  // A wheel did not turn under effort: blocked, or its encoder unplugged.
        CONFIG_DEFAULTS = 0x20,  // EEPROM config was missing or corrupt; defaults in use.
        LOCKSTEP = 0x40,  // The session runs in lockstep mode.
    };
    static const uint8_t MASK = 0x7F;
};

// Why an IDENTITY was sent.
enum class IdentityReason : uint8_t {
    BOOT = 0,  // Unsolicited boot announcement.
    HELLO_ACCEPTED = 1,  // Answer to a compatible HELLO: the session is open.
    HELLO_REJECTED = 2,  // Answer to a HELLO with another protocol version or spec hash: no session.
};
inline bool is_valid_IdentityReason(uint8_t value) {
    return value <= 2;
}

// Who drives the turn signals (SET_LIGHTS). Whatever the mode, FAILSAFE shows all four blinking fast; a reset and an accepted HELLO bring back the robot's power-up mode.
enum class LightsMode : uint8_t {
    AUTO = 0,  // From the motion state: the pair on the side of a turn, all four spinning in place, front and rear alternating out of ARMED.
    OFF = 1,  // All four dark.
    MANUAL = 2,  // Each lamp as the steady, slow and fast masks say: lit when it is in steady, or in slow during the on half of the 1.5 Hz blink, or in fast during the on half of the 3 Hz blink.
};
inline bool is_valid_LightsMode(uint8_t value) {
    return value <= 2;
}

// Severity of a LOG frame.
enum class LogLevel : uint8_t {
    DEBUG = 0,  // Developer detail.
    INFO = 1,  // Normal event.
    WARN = 2,  // Something the user should look at.
    ERROR = 3,  // Something failed.
};
inline bool is_valid_LogLevel(uint8_t value) {
    return value <= 3;
}

// decoder_counters: What a frame decoder counts (the firmware's and the SDK's alike): every received byte ends up in a valid frame or in bytes_discarded.
struct DecoderCounters {
    uint32_t frames_ok;  // Valid frames received.
    uint32_t crc_errors;  // Frames with a bad CRC.
    uint32_t cobs_errors;  // Chunks that were not valid COBS or were over-long.
    uint32_t length_errors;  // Frames whose length does not fit their msg_id.
    uint32_t unknown_ids;  // Frames with an unknown msg_id.
    uint32_t value_errors;  // Frames with a good CRC but a value the spec does not allow (e.g. an unknown enum value).
    uint32_t bytes_discarded;  // Received bytes that were not part of a valid frame.
};

// link_counters: What the firmware's link layer counts besides its decoder.
struct LinkCounters {
    uint32_t seq_gaps;  // Host frames missing according to seq.
    uint32_t duplicates;  // Reliable requests received again (answered, not re-applied).
    uint32_t frames_sent;  // Frames sent.
    uint32_t rx_overruns;  // Bytes lost because the receive buffer was full.
};

// Length rule of a msg_id: payload of min_payload..max_payload bytes; and its direction.
struct MessageBounds {
    uint8_t crc_extra;
    uint8_t min_payload;
    uint8_t max_payload;
    bool host_to_mcu;
};
// False for an msg_id the spec does not define (a table lookup).
bool message_bounds(uint8_t msg_id, MessageBounds& out);

// Returned by check_ranges() when every field is inside its spec range.
static const uint8_t ALL_FIELDS_VALID = 0xFF;

// HELLO (0x01, host to mcu, session): Opens (or restarts) a session. Repeated every HELLO_INTERVAL_MS until IDENTITY arrives. Motors are disabled while the session restarts.
struct ROVERLINK_PACKED Hello {
    enum : uint8_t { ID = 0x01, CRC_EXTRA = 0x77, PAYLOAD_SIZE = 9, PAYLOAD_MAX = 9 };
    enum : uint16_t { WATCHDOG_MS_MAX = 60000 };
    enum : uint8_t {  // field indices (NACK detail)
        FIELD_PROTOCOL_VERSION = 0,
        FIELD_SPEC_HASH = 1,
        FIELD_WATCHDOG_MS = 2,
        FIELD_FEEDBACK_MODE = 3,
        FIELD_FEEDBACK_HZ = 4,
    };
    uint8_t protocol_version;  // Protocol version the host was built for.
    uint32_t spec_hash;  // Spec hash the host was built from.
    uint16_t watchdog_ms;  // Requested watchdog period; 0 = stored default. The firmware clamps it to WATCHDOG_MIN_MS..WATCHDOG_MAX_MS. [ms]
    FeedbackMode feedback_mode;  // Stream or lockstep feedback.
    uint8_t feedback_hz;  // Requested stream rate; 0 = stored default. Clamped to 1..FEEDBACK_HZ_MAX. [Hz]
};
// Returns the payload length.
inline uint8_t pack(const Hello& m, uint8_t* payload) {
    memcpy(payload, &m, Hello::PAYLOAD_SIZE);
    return Hello::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
bool values_defined(const Hello& m);
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, Hello& m) {
    return layout::copy_payload(payload, len, Hello::PAYLOAD_SIZE, Hello::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
uint8_t check_ranges(const Hello& m);

// PING (0x02, host to mcu, session): Time-sync probe; answered by PONG.
struct ROVERLINK_PACKED Ping {
    enum : uint8_t { ID = 0x02, CRC_EXTRA = 0x8B, PAYLOAD_SIZE = 4, PAYLOAD_MAX = 4 };
    uint32_t host_time_us;  // Host clock at send time (low 32 bits), echoed in PONG. [us]
};
// Returns the payload length.
inline uint8_t pack(const Ping& m, uint8_t* payload) {
    memcpy(payload, &m, Ping::PAYLOAD_SIZE);
    return Ping::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
inline bool values_defined(const Ping&) { return true; }
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, Ping& m) {
    return layout::copy_payload(payload, len, Ping::PAYLOAD_SIZE, Ping::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
inline uint8_t check_ranges(const Ping&) { return ALL_FIELDS_VALID; }  // no ranged field

// ARM (0x10, host to mcu, reliable): Enables the motors and clears a latched FAILSAFE. Refused unless boot_id names the running boot, so an ARM from a previous session is never applied.
struct ROVERLINK_PACKED Arm {
    enum : uint8_t { ID = 0x10, CRC_EXTRA = 0x2A, PAYLOAD_SIZE = 4, PAYLOAD_MAX = 4 };
    uint32_t boot_id;  // boot_id from this session's IDENTITY.
};
// Returns the payload length.
inline uint8_t pack(const Arm& m, uint8_t* payload) {
    memcpy(payload, &m, Arm::PAYLOAD_SIZE);
    return Arm::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
inline bool values_defined(const Arm&) { return true; }
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, Arm& m) {
    return layout::copy_payload(payload, len, Arm::PAYLOAD_SIZE, Arm::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
inline uint8_t check_ranges(const Arm&) { return ALL_FIELDS_VALID; }  // no ranged field

// DISARM (0x11, host to mcu, reliable): Disables the motors (safe state) and clears a latched FAILSAFE.
struct ROVERLINK_PACKED Disarm {
    enum : uint8_t { ID = 0x11, CRC_EXTRA = 0x95, PAYLOAD_SIZE = 0, PAYLOAD_MAX = 0 };
};
inline uint8_t pack(const Disarm&, uint8_t*) { return 0; }
inline bool unpack(const uint8_t*, uint8_t len, Disarm&) { return len == 0; }
inline uint8_t check_ranges(const Disarm&) { return ALL_FIELDS_VALID; }

// SET_PID (0x12, host to mcu, reliable): Sets the velocity PID gains of one wheel (or all). Takes effect at the next control tick; the integrator is reset.
struct ROVERLINK_PACKED SetPid {
    enum : uint8_t { ID = 0x12, CRC_EXTRA = 0x34, PAYLOAD_SIZE = 21, PAYLOAD_MAX = 21 };
    enum : uint8_t {  // field indices (NACK detail)
        FIELD_WHEEL = 0,
        FIELD_KP = 1,
        FIELD_KI = 2,
        FIELD_KD = 3,
        FIELD_KF = 4,
        FIELD_KS = 5,
    };
    uint8_t wheel;  // Wheel index (0..WHEEL_COUNT-1) or PID_ALL_WHEELS.
    float kp;  // Proportional gain. [permille/(mm/s)]
    float ki;  // Integral gain (per second of error). [permille/mm]
    float kd;  // Derivative gain, on the measurement. [permille/(mm/s^2)]
    float kf;  // Feed-forward gain on the setpoint. [permille/(mm/s)]
    float ks;  // Static-friction feed-forward: the effort that keeps the wheel turning at the lowest speeds, added with the setpoint's sign. [permille]
};
// Returns the payload length.
inline uint8_t pack(const SetPid& m, uint8_t* payload) {
    memcpy(payload, &m, SetPid::PAYLOAD_SIZE);
    return SetPid::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
inline bool values_defined(const SetPid&) { return true; }
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, SetPid& m) {
    return layout::copy_payload(payload, len, SetPid::PAYLOAD_SIZE, SetPid::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
uint8_t check_ranges(const SetPid& m);

// GET_PID (0x13, host to mcu, reliable): Asks for one wheel's PID gains; answered by PID.
struct ROVERLINK_PACKED GetPid {
    enum : uint8_t { ID = 0x13, CRC_EXTRA = 0x6F, PAYLOAD_SIZE = 1, PAYLOAD_MAX = 1 };
    uint8_t wheel;  // Wheel index (0..WHEEL_COUNT-1).
};
// Returns the payload length.
inline uint8_t pack(const GetPid& m, uint8_t* payload) {
    memcpy(payload, &m, GetPid::PAYLOAD_SIZE);
    return GetPid::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
inline bool values_defined(const GetPid&) { return true; }
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, GetPid& m) {
    return layout::copy_payload(payload, len, GetPid::PAYLOAD_SIZE, GetPid::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
inline uint8_t check_ranges(const GetPid&) { return ALL_FIELDS_VALID; }  // no ranged field

// SET_CONFIG (0x14, host to mcu, reliable): Replaces the whole configuration (read it with GET_CONFIG, change, send back). Validated as a whole: NACK(OUT_OF_RANGE or INVALID_CONFIG, detail = field index) leaves the old one in place.
struct ROVERLINK_PACKED SetConfig {
    enum : uint8_t { ID = 0x14, CRC_EXTRA = 0xF8, PAYLOAD_SIZE = 40, PAYLOAD_MAX = 40 };
    enum : uint16_t { WATCHDOG_MS_MIN = 50, WATCHDOG_MS_MAX = 2000 };
    enum : uint16_t { ACCEL_LIMIT_MM_S2_MIN = 1 };
    enum : uint16_t { DECEL_LIMIT_MM_S2_MIN = 1 };
    enum : uint16_t { MAX_WHEEL_SPEED_MM_S_MIN = 1, MAX_WHEEL_SPEED_MM_S_MAX = 20000 };
    enum : uint16_t { MAX_EFFORT_PERMILLE_MAX = 1000 };
    enum : uint16_t { ENCODER_CPR_MIN = 1 };
    enum : uint8_t { ENCODER_INVERT_MAX = 3 };
    enum : uint8_t { MOTOR_INVERT_MAX = 3 };
    enum : uint32_t { WHEEL_DIAMETER_UM_MIN = 1000UL, WHEEL_DIAMETER_UM_MAX = 1000000UL };
    enum : uint16_t { STEERING_CENTER_CDEG_MAX = 18000 };
    enum : uint16_t { STEERING_MIN_CDEG_MAX = 18000 };
    enum : uint16_t { STEERING_MAX_CDEG_MAX = 18000 };
    enum : uint16_t { STEERING_STEP_CDEG_MAX = 9000 };
    enum : uint16_t { SERVO_MIN_US_MIN = 400, SERVO_MIN_US_MAX = 2600 };
    enum : uint16_t { SERVO_MAX_US_MIN = 400, SERVO_MAX_US_MAX = 2600 };
    enum : uint16_t { ESC_MIN_US_MIN = 800, ESC_MIN_US_MAX = 2200 };
    enum : uint16_t { ESC_NEUTRAL_US_MIN = 800, ESC_NEUTRAL_US_MAX = 2200 };
    enum : uint16_t { ESC_MAX_US_MIN = 800, ESC_MAX_US_MAX = 2200 };
    enum : uint16_t { ESC_ARM_MS_MAX = 10000 };
    enum : uint8_t { FEEDBACK_HZ_MIN = 1, FEEDBACK_HZ_MAX = 100 };
    enum : uint8_t {  // field indices (NACK detail)
        FIELD_WATCHDOG_MS = 0,
        FIELD_SAFE_STATE = 1,
        FIELD_ACCEL_LIMIT_MM_S2 = 2,
        FIELD_DECEL_LIMIT_MM_S2 = 3,
        FIELD_MAX_WHEEL_SPEED_MM_S = 4,
        FIELD_MAX_EFFORT_PERMILLE = 5,
        FIELD_ENCODER_CPR = 6,
        FIELD_ENCODER_INVERT = 7,
        FIELD_MOTOR_INVERT = 8,
        FIELD_WHEEL_DIAMETER_UM = 9,
        FIELD_STEERING_CENTER_CDEG = 10,
        FIELD_STEERING_MIN_CDEG = 11,
        FIELD_STEERING_MAX_CDEG = 12,
        FIELD_STEERING_STEP_CDEG = 13,
        FIELD_SERVO_MIN_US = 14,
        FIELD_SERVO_MAX_US = 15,
        FIELD_ESC_MIN_US = 16,
        FIELD_ESC_NEUTRAL_US = 17,
        FIELD_ESC_MAX_US = 18,
        FIELD_ESC_ARM_MS = 19,
        FIELD_FEEDBACK_HZ = 20,
    };
    uint16_t watchdog_ms;  // Default watchdog period (a HELLO may ask for another). [ms]
    SafeState safe_state;  // Motor behaviour in FAILSAFE and when disarmed.
    uint16_t accel_limit_mm_s2;  // Largest setpoint increase per second. [mm/s^2]
    uint16_t decel_limit_mm_s2;  // Largest setpoint decrease per second (also the RAMP_DOWN rate). [mm/s^2]
    uint16_t max_wheel_speed_mm_s;  // Setpoints beyond this are refused with NACK(OUT_OF_RANGE); lowering it re-limits the running setpoint at the next tick. [mm/s]
    uint16_t max_effort_permille;  // Motor effort limit (PID output clamp). [0.1 %]
    uint16_t encoder_cpr;  // Encoder counts per wheel revolution after decoding and gearing. [counts/rev]
    uint8_t encoder_invert;  // Bit i set: wheel i's encoder counts the other way.
    uint8_t motor_invert;  // Bit i set: wheel i's motor is wired the other way.
    uint32_t wheel_diameter_um;  // Wheel diameter, converts mm/s to counts/s. [um]
    uint16_t steering_center_cdeg;  // Servo angle that steers straight. [0.01 deg]
    uint16_t steering_min_cdeg;  // Smallest servo angle (full right). [0.01 deg]
    uint16_t steering_max_cdeg;  // Largest servo angle (full left). [0.01 deg]
    uint16_t steering_step_cdeg;  // Servo angles are quantised to centre + k * step (0: continuous). [0.01 deg]
    uint16_t servo_min_us;  // Servo pulse width at 0 degrees. [us]
    uint16_t servo_max_us;  // Servo pulse width at 180 degrees. [us]
    uint16_t esc_min_us;  // ESC pulse for full reverse. [us]
    uint16_t esc_neutral_us;  // ESC pulse for stop (sent during the boot calibration). [us]
    uint16_t esc_max_us;  // ESC pulse for full forward. [us]
    uint16_t esc_arm_ms;  // Arming sequence: neutral pulses held at boot before the ESC is driven. [ms]
    uint8_t feedback_hz;  // Default stream feedback rate. [Hz]
};
// Returns the payload length.
inline uint8_t pack(const SetConfig& m, uint8_t* payload) {
    memcpy(payload, &m, SetConfig::PAYLOAD_SIZE);
    return SetConfig::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
bool values_defined(const SetConfig& m);
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, SetConfig& m) {
    return layout::copy_payload(payload, len, SetConfig::PAYLOAD_SIZE, SetConfig::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
uint8_t check_ranges(const SetConfig& m);

// GET_CONFIG (0x15, host to mcu, reliable): Asks for the configuration; answered by CONFIG.
struct ROVERLINK_PACKED GetConfig {
    enum : uint8_t { ID = 0x15, CRC_EXTRA = 0x59, PAYLOAD_SIZE = 0, PAYLOAD_MAX = 0 };
};
inline uint8_t pack(const GetConfig&, uint8_t*) { return 0; }
inline bool unpack(const uint8_t*, uint8_t len, GetConfig&) { return len == 0; }
inline uint8_t check_ranges(const GetConfig&) { return ALL_FIELDS_VALID; }

// SAVE_CONFIG (0x16, host to mcu, reliable): Writes configuration and PID gains to EEPROM with a version and CRC; ACK after read-back verification.
struct ROVERLINK_PACKED SaveConfig {
    enum : uint8_t { ID = 0x16, CRC_EXTRA = 0x34, PAYLOAD_SIZE = 0, PAYLOAD_MAX = 0 };
};
inline uint8_t pack(const SaveConfig&, uint8_t*) { return 0; }
inline bool unpack(const uint8_t*, uint8_t len, SaveConfig&) { return len == 0; }
inline uint8_t check_ranges(const SaveConfig&) { return ALL_FIELDS_VALID; }

// RESET_ODOMETRY (0x17, host to mcu, reliable): Sets the cumulative encoder counts to zero.
struct ROVERLINK_PACKED ResetOdometry {
    enum : uint8_t { ID = 0x17, CRC_EXTRA = 0x85, PAYLOAD_SIZE = 0, PAYLOAD_MAX = 0 };
};
inline uint8_t pack(const ResetOdometry&, uint8_t*) { return 0; }
inline bool unpack(const uint8_t*, uint8_t len, ResetOdometry&) { return len == 0; }
inline uint8_t check_ranges(const ResetOdometry&) { return ALL_FIELDS_VALID; }

// GET_LINK_STATS (0x18, host to mcu, reliable): Asks for the firmware's link counters; answered by LINK_STATS.
struct ROVERLINK_PACKED GetLinkStats {
    enum : uint8_t { ID = 0x18, CRC_EXTRA = 0x6C, PAYLOAD_SIZE = 0, PAYLOAD_MAX = 0 };
};
inline uint8_t pack(const GetLinkStats&, uint8_t*) { return 0; }
inline bool unpack(const uint8_t*, uint8_t len, GetLinkStats&) { return len == 0; }
inline uint8_t check_ranges(const GetLinkStats&) { return ALL_FIELDS_VALID; }

// SET_LIGHTS (0x19, host to mcu, reliable): Chooses the turn signals' behaviour (capability TURN_SIGNALS, else NACK(UNSUPPORTED)), from the next control tick until another SET_LIGHTS, an accepted HELLO or a reset. The masks are kept in every mode (GET_LIGHTS reports them) but light lamps only in MANUAL.
struct ROVERLINK_PACKED SetLights {
    enum : uint8_t { ID = 0x19, CRC_EXTRA = 0x46, PAYLOAD_SIZE = 4, PAYLOAD_MAX = 4 };
    enum : uint8_t { STEADY_MAX = 15 };
    enum : uint8_t { SLOW_MAX = 15 };
    enum : uint8_t { FAST_MAX = 15 };
    enum : uint8_t {  // field indices (NACK detail)
        FIELD_MODE = 0,
        FIELD_STEADY = 1,
        FIELD_SLOW = 2,
        FIELD_FAST = 3,
    };
    LightsMode mode;  // Who drives the lights.
    uint8_t steady;  // MANUAL: lamps lit steadily (Lights bits).
    uint8_t slow;  // MANUAL: lamps blinking at 1.5 Hz, half on (Lights bits).
    uint8_t fast;  // MANUAL: lamps blinking at 3 Hz, half on (Lights bits).
};
// Returns the payload length.
inline uint8_t pack(const SetLights& m, uint8_t* payload) {
    memcpy(payload, &m, SetLights::PAYLOAD_SIZE);
    return SetLights::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
bool values_defined(const SetLights& m);
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, SetLights& m) {
    return layout::copy_payload(payload, len, SetLights::PAYLOAD_SIZE, SetLights::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
uint8_t check_ranges(const SetLights& m);

// GET_LIGHTS (0x1A, host to mcu, reliable): Asks for the turn signals' mode and the lamps lit; answered by LIGHTS_STATE (capability TURN_SIGNALS, else NACK(UNSUPPORTED)).
struct ROVERLINK_PACKED GetLights {
    enum : uint8_t { ID = 0x1A, CRC_EXTRA = 0xF4, PAYLOAD_SIZE = 0, PAYLOAD_MAX = 0 };
};
inline uint8_t pack(const GetLights&, uint8_t*) { return 0; }
inline bool unpack(const uint8_t*, uint8_t len, GetLights&) { return len == 0; }
inline uint8_t check_ranges(const GetLights&) { return ALL_FIELDS_VALID; }

// SET_WHEEL_SPEEDS (0x20, host to mcu, setpoint): Differential-drive setpoint: target speed of each wheel's rim. Stream mode: latest wins, applied at the next control tick. Lockstep: queued (LOCKSTEP_QUEUE), one applied per tick.
struct ROVERLINK_PACKED SetWheelSpeeds {
    enum : uint8_t { ID = 0x20, CRC_EXTRA = 0xC9, PAYLOAD_SIZE = 4, PAYLOAD_MAX = 4 };
    int16_t left_mm_s;  // Left wheel target speed, positive forward. [mm/s]
    int16_t right_mm_s;  // Right wheel target speed, positive forward. [mm/s]
};
// Returns the payload length.
inline uint8_t pack(const SetWheelSpeeds& m, uint8_t* payload) {
    memcpy(payload, &m, SetWheelSpeeds::PAYLOAD_SIZE);
    return SetWheelSpeeds::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
inline bool values_defined(const SetWheelSpeeds&) { return true; }
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, SetWheelSpeeds& m) {
    return layout::copy_payload(payload, len, SetWheelSpeeds::PAYLOAD_SIZE, SetWheelSpeeds::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
inline uint8_t check_ranges(const SetWheelSpeeds&) { return ALL_FIELDS_VALID; }  // no ranged field

// SET_ACKERMANN (0x21, host to mcu, setpoint): Ackermann setpoint: drive speed and front-wheel steering angle. Stream mode: latest wins, applied at the next control tick. Lockstep: queued (LOCKSTEP_QUEUE), one applied per tick.
struct ROVERLINK_PACKED SetAckermann {
    enum : uint8_t { ID = 0x21, CRC_EXTRA = 0x5D, PAYLOAD_SIZE = 4, PAYLOAD_MAX = 4 };
    enum : int16_t { STEERING_MRAD_MIN = -1571, STEERING_MRAD_MAX = 1571 };
    enum : uint8_t {  // field indices (NACK detail)
        FIELD_SPEED_MM_S = 0,
        FIELD_STEERING_MRAD = 1,
    };
    int16_t speed_mm_s;  // Target speed at the rear axle, positive forward. [mm/s]
    int16_t steering_mrad;  // Front-wheel angle, positive turns left. [mrad]
};
// Returns the payload length.
inline uint8_t pack(const SetAckermann& m, uint8_t* payload) {
    memcpy(payload, &m, SetAckermann::PAYLOAD_SIZE);
    return SetAckermann::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
inline bool values_defined(const SetAckermann&) { return true; }
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, SetAckermann& m) {
    return layout::copy_payload(payload, len, SetAckermann::PAYLOAD_SIZE, SetAckermann::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
uint8_t check_ranges(const SetAckermann& m);

// IDENTITY (0x81, mcu to host, session): Boot announcement (sent once, unsolicited, after reset) and the answer to every HELLO.
struct ROVERLINK_PACKED Identity {
    enum : uint8_t { ID = 0x81, CRC_EXTRA = 0x2B, PAYLOAD_SIZE = 25, PAYLOAD_MAX = 49 };
    uint8_t protocol_version;  // Protocol version the firmware was built for.
    uint32_t spec_hash;  // Spec hash the firmware was built from.
    uint8_t firmware_version[3];  // Firmware major, minor, patch.
    Board board;  // Board the firmware runs on.
    uint16_t capabilities;  // What this build can do.
    uint32_t boot_id;  // Random per boot; changes on every reset.
    uint32_t uptime_ms;  // Time since boot. [ms]
    IdentityReason reason;  // Boot announcement, or the answer to a HELLO.
    uint8_t hello_seq;  // seq of the HELLO answered (0 for the boot announcement).
    uint16_t watchdog_ms;  // Watchdog period granted for this session. [ms]
    FeedbackMode feedback_mode;  // Feedback mode granted for this session.
    uint8_t feedback_hz;  // Stream rate granted for this session. [Hz]
    char robot_name[24];  // Name of the firmware example (ASCII).
    uint8_t robot_name_len;  // bytes used in robot_name
};
// Returns the payload length.
inline uint8_t pack(const Identity& m, uint8_t* payload) {
    return layout::pack_tail(&m, Identity::PAYLOAD_SIZE, m.robot_name_len, 24, payload);
}
// Whether every enum, flags and char field holds a value the spec defines.
bool values_defined(const Identity& m);
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, Identity& m) {
    return layout::copy_payload(payload, len, Identity::PAYLOAD_SIZE, Identity::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
uint8_t check_ranges(const Identity& m);

// PONG (0x82, mcu to host, session): Answer to PING.
struct ROVERLINK_PACKED Pong {
    enum : uint8_t { ID = 0x82, CRC_EXTRA = 0xE6, PAYLOAD_SIZE = 8, PAYLOAD_MAX = 8 };
    uint32_t host_time_us;  // host_time_us of the PING. [us]
    uint32_t mcu_time_us;  // MCU clock when the PING was processed. [us]
};
// Returns the payload length.
inline uint8_t pack(const Pong& m, uint8_t* payload) {
    memcpy(payload, &m, Pong::PAYLOAD_SIZE);
    return Pong::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
inline bool values_defined(const Pong&) { return true; }
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, Pong& m) {
    return layout::copy_payload(payload, len, Pong::PAYLOAD_SIZE, Pong::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
inline uint8_t check_ranges(const Pong&) { return ALL_FIELDS_VALID; }  // no ranged field

// ACK (0x83, mcu to host, reliable): A reliable request was applied (or was a duplicate of one already applied).
struct ROVERLINK_PACKED Ack {
    enum : uint8_t { ID = 0x83, CRC_EXTRA = 0x34, PAYLOAD_SIZE = 2, PAYLOAD_MAX = 2 };
    uint8_t req_id;  // msg_id of the request.
    uint8_t req_seq;  // seq of the request.
};
// Returns the payload length.
inline uint8_t pack(const Ack& m, uint8_t* payload) {
    memcpy(payload, &m, Ack::PAYLOAD_SIZE);
    return Ack::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
inline bool values_defined(const Ack&) { return true; }
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, Ack& m) {
    return layout::copy_payload(payload, len, Ack::PAYLOAD_SIZE, Ack::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
inline uint8_t check_ranges(const Ack&) { return ALL_FIELDS_VALID; }  // no ranged field

// NACK (0x84, mcu to host, reliable): A request was refused. Also answers setpoints that cannot be applied.
struct ROVERLINK_PACKED Nack {
    enum : uint8_t { ID = 0x84, CRC_EXTRA = 0xC6, PAYLOAD_SIZE = 4, PAYLOAD_MAX = 4 };
    uint8_t req_id;  // msg_id of the request.
    uint8_t req_seq;  // seq of the request.
    NackReason reason;  // Why.
    uint8_t detail;  // Reason-specific: field index, FailsafeReason, ...
};
// Returns the payload length.
inline uint8_t pack(const Nack& m, uint8_t* payload) {
    memcpy(payload, &m, Nack::PAYLOAD_SIZE);
    return Nack::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
bool values_defined(const Nack& m);
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, Nack& m) {
    return layout::copy_payload(payload, len, Nack::PAYLOAD_SIZE, Nack::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
uint8_t check_ranges(const Nack& m);

// PID (0x85, mcu to host, reliable): Answer to GET_PID.
struct ROVERLINK_PACKED Pid {
    enum : uint8_t { ID = 0x85, CRC_EXTRA = 0x09, PAYLOAD_SIZE = 22, PAYLOAD_MAX = 22 };
    uint8_t req_seq;  // seq of the GET_PID.
    uint8_t wheel;  // Wheel index.
    float kp;  // Proportional gain. [permille/(mm/s)]
    float ki;  // Integral gain (per second of error). [permille/mm]
    float kd;  // Derivative gain, on the measurement. [permille/(mm/s^2)]
    float kf;  // Feed-forward gain on the setpoint. [permille/(mm/s)]
    float ks;  // Static-friction feed-forward: the effort that keeps the wheel turning at the lowest speeds, added with the setpoint's sign. [permille]
};
// Returns the payload length.
inline uint8_t pack(const Pid& m, uint8_t* payload) {
    memcpy(payload, &m, Pid::PAYLOAD_SIZE);
    return Pid::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
inline bool values_defined(const Pid&) { return true; }
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, Pid& m) {
    return layout::copy_payload(payload, len, Pid::PAYLOAD_SIZE, Pid::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
uint8_t check_ranges(const Pid& m);

// CONFIG (0x86, mcu to host, reliable): Answer to GET_CONFIG.
struct ROVERLINK_PACKED Config {
    enum : uint8_t { ID = 0x86, CRC_EXTRA = 0x18, PAYLOAD_SIZE = 41, PAYLOAD_MAX = 41 };
    enum : uint16_t { WATCHDOG_MS_MIN = 50, WATCHDOG_MS_MAX = 2000 };
    enum : uint16_t { ACCEL_LIMIT_MM_S2_MIN = 1 };
    enum : uint16_t { DECEL_LIMIT_MM_S2_MIN = 1 };
    enum : uint16_t { MAX_WHEEL_SPEED_MM_S_MIN = 1, MAX_WHEEL_SPEED_MM_S_MAX = 20000 };
    enum : uint16_t { MAX_EFFORT_PERMILLE_MAX = 1000 };
    enum : uint16_t { ENCODER_CPR_MIN = 1 };
    enum : uint8_t { ENCODER_INVERT_MAX = 3 };
    enum : uint8_t { MOTOR_INVERT_MAX = 3 };
    enum : uint32_t { WHEEL_DIAMETER_UM_MIN = 1000UL, WHEEL_DIAMETER_UM_MAX = 1000000UL };
    enum : uint16_t { STEERING_CENTER_CDEG_MAX = 18000 };
    enum : uint16_t { STEERING_MIN_CDEG_MAX = 18000 };
    enum : uint16_t { STEERING_MAX_CDEG_MAX = 18000 };
    enum : uint16_t { STEERING_STEP_CDEG_MAX = 9000 };
    enum : uint16_t { SERVO_MIN_US_MIN = 400, SERVO_MIN_US_MAX = 2600 };
    enum : uint16_t { SERVO_MAX_US_MIN = 400, SERVO_MAX_US_MAX = 2600 };
    enum : uint16_t { ESC_MIN_US_MIN = 800, ESC_MIN_US_MAX = 2200 };
    enum : uint16_t { ESC_NEUTRAL_US_MIN = 800, ESC_NEUTRAL_US_MAX = 2200 };
    enum : uint16_t { ESC_MAX_US_MIN = 800, ESC_MAX_US_MAX = 2200 };
    enum : uint16_t { ESC_ARM_MS_MAX = 10000 };
    enum : uint8_t { FEEDBACK_HZ_MIN = 1, FEEDBACK_HZ_MAX = 100 };
    uint8_t req_seq;  // seq of the GET_CONFIG.
    uint16_t watchdog_ms;  // Default watchdog period (a HELLO may ask for another). [ms]
    SafeState safe_state;  // Motor behaviour in FAILSAFE and when disarmed.
    uint16_t accel_limit_mm_s2;  // Largest setpoint increase per second. [mm/s^2]
    uint16_t decel_limit_mm_s2;  // Largest setpoint decrease per second (also the RAMP_DOWN rate). [mm/s^2]
    uint16_t max_wheel_speed_mm_s;  // Setpoints beyond this are refused with NACK(OUT_OF_RANGE); lowering it re-limits the running setpoint at the next tick. [mm/s]
    uint16_t max_effort_permille;  // Motor effort limit (PID output clamp). [0.1 %]
    uint16_t encoder_cpr;  // Encoder counts per wheel revolution after decoding and gearing. [counts/rev]
    uint8_t encoder_invert;  // Bit i set: wheel i's encoder counts the other way.
    uint8_t motor_invert;  // Bit i set: wheel i's motor is wired the other way.
    uint32_t wheel_diameter_um;  // Wheel diameter, converts mm/s to counts/s. [um]
    uint16_t steering_center_cdeg;  // Servo angle that steers straight. [0.01 deg]
    uint16_t steering_min_cdeg;  // Smallest servo angle (full right). [0.01 deg]
    uint16_t steering_max_cdeg;  // Largest servo angle (full left). [0.01 deg]
    uint16_t steering_step_cdeg;  // Servo angles are quantised to centre + k * step (0: continuous). [0.01 deg]
    uint16_t servo_min_us;  // Servo pulse width at 0 degrees. [us]
    uint16_t servo_max_us;  // Servo pulse width at 180 degrees. [us]
    uint16_t esc_min_us;  // ESC pulse for full reverse. [us]
    uint16_t esc_neutral_us;  // ESC pulse for stop (sent during the boot calibration). [us]
    uint16_t esc_max_us;  // ESC pulse for full forward. [us]
    uint16_t esc_arm_ms;  // Arming sequence: neutral pulses held at boot before the ESC is driven. [ms]
    uint8_t feedback_hz;  // Default stream feedback rate. [Hz]
};
// Returns the payload length.
inline uint8_t pack(const Config& m, uint8_t* payload) {
    memcpy(payload, &m, Config::PAYLOAD_SIZE);
    return Config::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
bool values_defined(const Config& m);
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, Config& m) {
    return layout::copy_payload(payload, len, Config::PAYLOAD_SIZE, Config::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
uint8_t check_ranges(const Config& m);

// LINK_STATS (0x87, mcu to host, reliable): Answer to GET_LINK_STATS: the firmware's receive and transmit counters since boot.
struct ROVERLINK_PACKED LinkStats {
    enum : uint8_t { ID = 0x87, CRC_EXTRA = 0xA1, PAYLOAD_SIZE = 45, PAYLOAD_MAX = 45 };
    uint8_t req_seq;  // seq of the GET_LINK_STATS.
    uint32_t frames_ok;  // Valid frames received.
    uint32_t crc_errors;  // Frames with a bad CRC.
    uint32_t cobs_errors;  // Chunks that were not valid COBS or were over-long.
    uint32_t length_errors;  // Frames whose length does not fit their msg_id.
    uint32_t unknown_ids;  // Frames with an unknown msg_id.
    uint32_t value_errors;  // Frames with a good CRC but a value the spec does not allow (e.g. an unknown enum value).
    uint32_t bytes_discarded;  // Received bytes that were not part of a valid frame.
    uint32_t seq_gaps;  // Host frames missing according to seq.
    uint32_t duplicates;  // Reliable requests received again (answered, not re-applied).
    uint32_t frames_sent;  // Frames sent.
    uint32_t rx_overruns;  // Bytes lost because the receive buffer was full.
};
// Returns the payload length.
inline uint8_t pack(const LinkStats& m, uint8_t* payload) {
    memcpy(payload, &m, LinkStats::PAYLOAD_SIZE);
    return LinkStats::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
inline bool values_defined(const LinkStats&) { return true; }
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, LinkStats& m) {
    return layout::copy_payload(payload, len, LinkStats::PAYLOAD_SIZE, LinkStats::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
inline uint8_t check_ranges(const LinkStats&) { return ALL_FIELDS_VALID; }  // no ranged field

// LIGHTS_STATE (0x88, mcu to host, reliable): Answer to GET_LIGHTS: the mode in force, its masks, and the lamps lit by the last control tick.
struct ROVERLINK_PACKED LightsState {
    enum : uint8_t { ID = 0x88, CRC_EXTRA = 0xD9, PAYLOAD_SIZE = 6, PAYLOAD_MAX = 6 };
    enum : uint8_t { STEADY_MAX = 15 };
    enum : uint8_t { SLOW_MAX = 15 };
    enum : uint8_t { FAST_MAX = 15 };
    enum : uint8_t { LIT_MAX = 15 };
    uint8_t req_seq;  // seq of the GET_LIGHTS.
    LightsMode mode;  // Who drives the lights.
    uint8_t steady;  // MANUAL: lamps lit steadily (Lights bits).
    uint8_t slow;  // MANUAL: lamps blinking at 1.5 Hz, half on (Lights bits).
    uint8_t fast;  // MANUAL: lamps blinking at 3 Hz, half on (Lights bits).
    uint8_t lit;  // Lamps lit at the last control tick (Lights bits).
};
// Returns the payload length.
inline uint8_t pack(const LightsState& m, uint8_t* payload) {
    memcpy(payload, &m, LightsState::PAYLOAD_SIZE);
    return LightsState::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
bool values_defined(const LightsState& m);
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, LightsState& m) {
    return layout::copy_payload(payload, len, LightsState::PAYLOAD_SIZE, LightsState::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
uint8_t check_ranges(const LightsState& m);

// FEEDBACK (0x90, mcu to host, telemetry): Robot state at one control tick. Streamed every round(CONTROL_RATE_HZ / feedback_hz) ticks: before any HELLO at the config's rate; in a stream session at the session's feedback_hz; in a lockstep session while it is not ARMED (DISARMED, FAILSAFE) as in stream mode, the first in the first tick out of ARMED. In a lockstep session while ARMED: exactly one in each tick that applied a setpoint, none in any other.
struct ROVERLINK_PACKED Feedback {
    enum : uint8_t { ID = 0x90, CRC_EXTRA = 0x3F, PAYLOAD_SIZE = 33, PAYLOAD_MAX = 33 };
    enum : int16_t { EFFORT_PERMILLE_MIN = -1000, EFFORT_PERMILLE_MAX = 1000 };
    enum : int16_t { STEERING_MRAD_MIN = -1571, STEERING_MRAD_MAX = 1571 };
    uint32_t boot_id;  // boot_id of the running boot: a change means the board was reset.
    uint32_t mcu_time_us;  // MCU clock at the tick (wraps every 71.6 min; the host unwraps it). [us]
    uint16_t tick;  // Control tick counter (wraps; the host unwraps it).
    uint8_t ack_seq;  // seq of the last setpoint applied.
    uint16_t ack_tick;  // tick at which that setpoint was applied.
    uint8_t status;  // Status bits.
    FailsafeReason failsafe_reason;  // Latched failsafe reason (NONE when not in failsafe).
    int32_t encoder_counts[2];  // Cumulative encoder counts per wheel, captured atomically (wraps at 2^32).
    int16_t wheel_speed_mm_s[2];  // Measured wheel speeds. [mm/s]
    int16_t effort_permille[2];  // Motor efforts applied (negative: reverse). [0.1 %]
    int16_t steering_mrad;  // Front-wheel angle commanded to the servo (0 without steering). [mrad]
};
// Returns the payload length.
inline uint8_t pack(const Feedback& m, uint8_t* payload) {
    memcpy(payload, &m, Feedback::PAYLOAD_SIZE);
    return Feedback::PAYLOAD_SIZE;
}
// Whether every enum, flags and char field holds a value the spec defines.
bool values_defined(const Feedback& m);
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, Feedback& m) {
    return layout::copy_payload(payload, len, Feedback::PAYLOAD_SIZE, Feedback::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
uint8_t check_ranges(const Feedback& m);

// LOG (0x91, mcu to host, telemetry): A short text from the firmware. The firmware never prints text on the port; this is its only text channel.
struct ROVERLINK_PACKED Log {
    enum : uint8_t { ID = 0x91, CRC_EXTRA = 0x13, PAYLOAD_SIZE = 1, PAYLOAD_MAX = 61 };
    LogLevel level;  // Severity.
    char text[60];  // ASCII text.
    uint8_t text_len;  // bytes used in text
};
// Returns the payload length.
inline uint8_t pack(const Log& m, uint8_t* payload) {
    return layout::pack_tail(&m, Log::PAYLOAD_SIZE, m.text_len, 60, payload);
}
// Whether every enum, flags and char field holds a value the spec defines.
bool values_defined(const Log& m);
// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).
inline bool unpack(const uint8_t* payload, uint8_t len, Log& m) {
    return layout::copy_payload(payload, len, Log::PAYLOAD_SIZE, Log::PAYLOAD_MAX, &m) && values_defined(m);
}
// Index of the first field outside its spec range (an undefined enum value or flag bit included),
// or ALL_FIELDS_VALID.
uint8_t check_ranges(const Log& m);

enum DispatchResult : uint8_t {
    DISPATCH_OK = 0,
    DISPATCH_UNKNOWN_ID,
    DISPATCH_BAD_PAYLOAD,     // wrong length or a value the spec does not allow
    DISPATCH_WRONG_DIRECTION  // a known message that this side never receives
};

// Every host_to_mcu message, one at a time.
union HostToMcu {
    Hello hello;
    Ping ping;
    Arm arm;
    Disarm disarm;
    SetPid set_pid;
    GetPid get_pid;
    SetConfig set_config;
    GetConfig get_config;
    SaveConfig save_config;
    ResetOdometry reset_odometry;
    GetLinkStats get_link_stats;
    SetLights set_lights;
    GetLights get_lights;
    SetWheelSpeeds set_wheel_speeds;
    SetAckermann set_ackermann;
};
// Unpacks a host_to_mcu payload into the member of `m` that msg_id names (one table lookup,
// one copy and its checks): DISPATCH_OK, _BAD_PAYLOAD, _WRONG_DIRECTION or _UNKNOWN_ID.
// A reliable request's values (enum, flag bit, ASCII) are left to its check_ranges(): the
// firmware answers a value the spec does not define with NACK(OUT_OF_RANGE, the field).
DispatchResult unpack_host_to_mcu(uint8_t msg_id, const uint8_t* payload, uint8_t len, HostToMcu& m);
// The same with msg_id's bounds already looked up (FrameDecoder::bounds() after a FRAME).
DispatchResult unpack_host_to_mcu(const MessageBounds& b, uint8_t msg_id, const uint8_t* payload, uint8_t len,
                                 HostToMcu& m);

// Decodes a payload and calls h.handle(const Msg&, seq) for host_to_mcu messages (firmware).
template <class Handler>
DispatchResult dispatch_host_to_mcu(uint8_t msg_id, uint8_t seq, const uint8_t* payload, uint8_t len, Handler& h) {
    HostToMcu m;
    const DispatchResult r = unpack_host_to_mcu(msg_id, payload, len, m);
    if (r != DISPATCH_OK) return r;
    switch (msg_id) {
    case Hello::ID:
        h.handle(m.hello, seq);
        break;
    case Ping::ID:
        h.handle(m.ping, seq);
        break;
    case Arm::ID:
        h.handle(m.arm, seq);
        break;
    case Disarm::ID:
        h.handle(m.disarm, seq);
        break;
    case SetPid::ID:
        h.handle(m.set_pid, seq);
        break;
    case GetPid::ID:
        h.handle(m.get_pid, seq);
        break;
    case SetConfig::ID:
        h.handle(m.set_config, seq);
        break;
    case GetConfig::ID:
        h.handle(m.get_config, seq);
        break;
    case SaveConfig::ID:
        h.handle(m.save_config, seq);
        break;
    case ResetOdometry::ID:
        h.handle(m.reset_odometry, seq);
        break;
    case GetLinkStats::ID:
        h.handle(m.get_link_stats, seq);
        break;
    case SetLights::ID:
        h.handle(m.set_lights, seq);
        break;
    case GetLights::ID:
        h.handle(m.get_lights, seq);
        break;
    case SetWheelSpeeds::ID:
        h.handle(m.set_wheel_speeds, seq);
        break;
    case SetAckermann::ID:
        h.handle(m.set_ackermann, seq);
        break;
    }
    return DISPATCH_OK;
}

// Every mcu_to_host message, one at a time.
union McuToHost {
    Identity identity;
    Pong pong;
    Ack ack;
    Nack nack;
    Pid pid;
    Config config;
    LinkStats link_stats;
    LightsState lights_state;
    Feedback feedback;
    Log log;
};
// Unpacks a mcu_to_host payload into the member of `m` that msg_id names (one table lookup,
// one copy and its checks): DISPATCH_OK, _BAD_PAYLOAD, _WRONG_DIRECTION or _UNKNOWN_ID.
DispatchResult unpack_mcu_to_host(uint8_t msg_id, const uint8_t* payload, uint8_t len, McuToHost& m);
// The same with msg_id's bounds already looked up (FrameDecoder::bounds() after a FRAME).
DispatchResult unpack_mcu_to_host(const MessageBounds& b, uint8_t msg_id, const uint8_t* payload, uint8_t len,
                                 McuToHost& m);

// Decodes a payload and calls h.handle(const Msg&, seq) for mcu_to_host messages (host-side tools).
template <class Handler>
DispatchResult dispatch_mcu_to_host(uint8_t msg_id, uint8_t seq, const uint8_t* payload, uint8_t len, Handler& h) {
    McuToHost m;
    const DispatchResult r = unpack_mcu_to_host(msg_id, payload, len, m);
    if (r != DISPATCH_OK) return r;
    switch (msg_id) {
    case Identity::ID:
        h.handle(m.identity, seq);
        break;
    case Pong::ID:
        h.handle(m.pong, seq);
        break;
    case Ack::ID:
        h.handle(m.ack, seq);
        break;
    case Nack::ID:
        h.handle(m.nack, seq);
        break;
    case Pid::ID:
        h.handle(m.pid, seq);
        break;
    case Config::ID:
        h.handle(m.config, seq);
        break;
    case LinkStats::ID:
        h.handle(m.link_stats, seq);
        break;
    case LightsState::ID:
        h.handle(m.lights_state, seq);
        break;
    case Feedback::ID:
        h.handle(m.feedback, seq);
        break;
    case Log::ID:
        h.handle(m.log, seq);
        break;
    }
    return DISPATCH_OK;
}

// Session state machine (Firmware session: one per boot; the host drives it with HELLO, ARM and DISARM and the watchdog ends it.)
enum class SessionState : uint8_t {
    BOOT = 0,  // Hardware and config initialising; motors disabled.
    IDLE = 1,  // Booted and announced; no session. Waits for a compatible HELLO.
    DISARMED = 2,  // Session open; motors in safe state; reliable requests accepted.
    ARMED = 3,  // Motors enabled; setpoints applied; the watchdog runs.
    FAILSAFE = 4,  // Latched after a watchdog expiry or fault; motors in safe state until re-ARM or DISARM.
};
enum class SessionEvent : uint8_t {
    INIT_DONE = 0,  // Hardware and config are ready.
    HELLO = 1,  // A HELLO frame arrived.
    ARM = 2,  // An ARM frame arrived.
    DISARM = 3,  // A DISARM frame arrived.
    SETPOINT = 4,  // A setpoint frame arrived.
    VALID_FRAME = 5,  // Any valid host frame arrived (before its own event).
    WATCHDOG_EXPIRED = 6,  // No valid host frame for the watchdog period (checked every control tick).
    FAULT = 7,  // The control loop found a fault (encoder, config, supply).
    RESET = 8,  // Reset request, brown-out or watchdog reset of the MCU.
};
enum class Guard : uint8_t {
    COMPATIBLE = 1,  // HELLO's protocol_version and spec_hash equal the firmware's.
    BOOT_ID_MATCHES = 2,  // ARM's boot_id equals this boot's boot_id.
};
static const uint8_t SESSION_STATE_COUNT = 5;
static const SessionState INITIAL_STATE = SessionState::BOOT;
struct Action {
    enum : uint16_t {
        ANNOUNCE = 1u << 0,  // Send the boot IDENTITY (reason BOOT).
        ACCEPT_HELLO = 1u << 1,  // Apply the requested watchdog and feedback mode (clamped); answer IDENTITY(HELLO_ACCEPTED).
        REJECT_HELLO = 1u << 2,  // Answer IDENTITY(HELLO_REJECTED) so the host can report both hashes.
        MOTORS_SAFE = 1u << 3,  // Put the motors in the configured safe state and the steering at centre; clear setpoints and integrators.
        MOTORS_ENABLE = 1u << 4,  // Let the control loop drive the motors from setpoints.
        FEED_WATCHDOG = 1u << 5,  // Restart the watchdog period.
        LATCH_REASON = 1u << 6,  // Record the failsafe reason and report it in FEEDBACK.
        CLEAR_REASON = 1u << 7,  // Clear the latched failsafe reason.
        ACK = 1u << 8,  // Answer ACK with the request's id and seq.
        NACK = 1u << 9,  // Answer NACK with the request's id and seq and the reason for this state.
        APPLY_SETPOINT = 1u << 10,  // Store the setpoint: stream mode, the next control tick applies it (latest wins); lockstep, it joins the queue (LOCKSTEP_QUEUE), each tick applying the oldest.
    };
};

// One row per transition, grouped by event (spec order within an event), 5 bytes: source
// states (bit i: SessionState i), guard (GUARD_NONE, or a Guard with GUARD_NEGATED), target
// (TARGET_STAY: the source state), actions low byte, actions high byte. EVENT_ROWS[e] is the first
// row of event e, EVENT_ROWS[e + 1] the end of its rows. Kept in flash on AVR.
static const uint8_t TRANSITION_COUNT = 17;
static const uint8_t EVENT_COUNT = 9;
static const uint8_t GUARD_NONE = 0xFF;
static const uint8_t GUARD_NEGATED = 0x80;
static const uint8_t TARGET_STAY = 0xFF;
extern const uint8_t TRANSITIONS[TRANSITION_COUNT][5] ROVERLINK_PROGMEM;
extern const uint8_t EVENT_ROWS[EVENT_COUNT + 1] ROVERLINK_PROGMEM;

struct StepResult {
    bool matched;        // false: no row, stay and do nothing
    SessionState target;
    uint16_t actions;    // Action bits
};

// First row for (state, event) whose guard holds; guards.check(Guard) evaluates guards.
template <class Guards>
StepResult step(SessionState state, SessionEvent event, Guards& guards) {
    StepResult r = {false, state, 0};
    const uint8_t e = static_cast<uint8_t>(event);
    const uint8_t end = ROVERLINK_READ_BYTE(&EVENT_ROWS[e + 1]);
    for (uint8_t i = ROVERLINK_READ_BYTE(&EVENT_ROWS[e]); i < end; ++i) {
        const uint8_t* row = TRANSITIONS[i];
        if (!((ROVERLINK_READ_BYTE(row) >> static_cast<uint8_t>(state)) & 1u)) {
            continue;
        }
        const uint8_t g = ROVERLINK_READ_BYTE(row + 1);
        if (g != GUARD_NONE) {
            const bool holds = guards.check(static_cast<Guard>(g & 0x7F));
            if (holds == ((g & GUARD_NEGATED) != 0)) continue;
        }
        const uint8_t target = ROVERLINK_READ_BYTE(row + 2);
        r.matched = true;
        if (target != TARGET_STAY) r.target = static_cast<SessionState>(target);
        r.actions = static_cast<uint16_t>(ROVERLINK_READ_BYTE(row + 3) |
                                          (ROVERLINK_READ_BYTE(row + 4) << 8));
        return r;
    }
    return r;
}

}  // namespace proto
}  // namespace roverlink

#endif  // ROVERLINK_GENERATED_PROTOCOL_H
