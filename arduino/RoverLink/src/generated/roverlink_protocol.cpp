// DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
// spec hash: 0x163FE6FE
#include "roverlink_protocol.h"

namespace roverlink {
namespace proto {

// Every struct member has the width of its wire field (no int, no double; AVR and ARM agree),
// and every member offset fits the byte a layout keeps it in.
static_assert(ALL_FIELDS_VALID == layout::ALL_VALID, "check_ranges() answers the layout walker's");
static_assert(Hello::PAYLOAD_MAX <= MAX_PAYLOAD, "HELLO payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Hello::protocol_version) + sizeof(Hello::spec_hash) + sizeof(Hello::watchdog_ms) + sizeof(Hello::feedback_mode) + sizeof(Hello::feedback_hz) == Hello::PAYLOAD_MAX, "HELLO member widths differ from the wire");
static_assert(sizeof(Hello) < 256, "HELLO member offsets must fit in a byte");
static_assert(Ping::PAYLOAD_MAX <= MAX_PAYLOAD, "PING payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Ping::host_time_us) == Ping::PAYLOAD_MAX, "PING member widths differ from the wire");
static_assert(sizeof(Ping) < 256, "PING member offsets must fit in a byte");
static_assert(Arm::PAYLOAD_MAX <= MAX_PAYLOAD, "ARM payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Arm::boot_id) == Arm::PAYLOAD_MAX, "ARM member widths differ from the wire");
static_assert(sizeof(Arm) < 256, "ARM member offsets must fit in a byte");
static_assert(Disarm::PAYLOAD_MAX <= MAX_PAYLOAD, "DISARM payload exceeds MAX_PAYLOAD");
static_assert(SetPid::PAYLOAD_MAX <= MAX_PAYLOAD, "SET_PID payload exceeds MAX_PAYLOAD");
static_assert(sizeof(SetPid::wheel) + sizeof(SetPid::kp) + sizeof(SetPid::ki) + sizeof(SetPid::kd) + sizeof(SetPid::kf) == SetPid::PAYLOAD_MAX, "SET_PID member widths differ from the wire");
static_assert(sizeof(SetPid) < 256, "SET_PID member offsets must fit in a byte");
static_assert(GetPid::PAYLOAD_MAX <= MAX_PAYLOAD, "GET_PID payload exceeds MAX_PAYLOAD");
static_assert(sizeof(GetPid::wheel) == GetPid::PAYLOAD_MAX, "GET_PID member widths differ from the wire");
static_assert(sizeof(GetPid) < 256, "GET_PID member offsets must fit in a byte");
static_assert(SetConfig::PAYLOAD_MAX <= MAX_PAYLOAD, "SET_CONFIG payload exceeds MAX_PAYLOAD");
static_assert(sizeof(SetConfig::watchdog_ms) + sizeof(SetConfig::safe_state) + sizeof(SetConfig::accel_limit_mm_s2) + sizeof(SetConfig::decel_limit_mm_s2) + sizeof(SetConfig::max_wheel_speed_mm_s) + sizeof(SetConfig::max_effort_permille) + sizeof(SetConfig::encoder_cpr) + sizeof(SetConfig::encoder_invert) + sizeof(SetConfig::motor_invert) + sizeof(SetConfig::wheel_diameter_um) + sizeof(SetConfig::steering_center_cdeg) + sizeof(SetConfig::steering_min_cdeg) + sizeof(SetConfig::steering_max_cdeg) + sizeof(SetConfig::steering_step_cdeg) + sizeof(SetConfig::servo_min_us) + sizeof(SetConfig::servo_max_us) + sizeof(SetConfig::esc_min_us) + sizeof(SetConfig::esc_neutral_us) + sizeof(SetConfig::esc_max_us) + sizeof(SetConfig::esc_arm_ms) + sizeof(SetConfig::feedback_hz) == SetConfig::PAYLOAD_MAX, "SET_CONFIG member widths differ from the wire");
static_assert(sizeof(SetConfig) < 256, "SET_CONFIG member offsets must fit in a byte");
static_assert(GetConfig::PAYLOAD_MAX <= MAX_PAYLOAD, "GET_CONFIG payload exceeds MAX_PAYLOAD");
static_assert(SaveConfig::PAYLOAD_MAX <= MAX_PAYLOAD, "SAVE_CONFIG payload exceeds MAX_PAYLOAD");
static_assert(ResetOdometry::PAYLOAD_MAX <= MAX_PAYLOAD, "RESET_ODOMETRY payload exceeds MAX_PAYLOAD");
static_assert(GetLinkStats::PAYLOAD_MAX <= MAX_PAYLOAD, "GET_LINK_STATS payload exceeds MAX_PAYLOAD");
static_assert(SetWheelSpeeds::PAYLOAD_MAX <= MAX_PAYLOAD, "SET_WHEEL_SPEEDS payload exceeds MAX_PAYLOAD");
static_assert(sizeof(SetWheelSpeeds::left_mm_s) + sizeof(SetWheelSpeeds::right_mm_s) == SetWheelSpeeds::PAYLOAD_MAX, "SET_WHEEL_SPEEDS member widths differ from the wire");
static_assert(sizeof(SetWheelSpeeds) < 256, "SET_WHEEL_SPEEDS member offsets must fit in a byte");
static_assert(SetAckermann::PAYLOAD_MAX <= MAX_PAYLOAD, "SET_ACKERMANN payload exceeds MAX_PAYLOAD");
static_assert(sizeof(SetAckermann::speed_mm_s) + sizeof(SetAckermann::steering_mrad) == SetAckermann::PAYLOAD_MAX, "SET_ACKERMANN member widths differ from the wire");
static_assert(sizeof(SetAckermann) < 256, "SET_ACKERMANN member offsets must fit in a byte");
static_assert(Identity::PAYLOAD_MAX <= MAX_PAYLOAD, "IDENTITY payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Identity::protocol_version) + sizeof(Identity::spec_hash) + sizeof(Identity::firmware_version) + sizeof(Identity::board) + sizeof(Identity::capabilities) + sizeof(Identity::boot_id) + sizeof(Identity::uptime_ms) + sizeof(Identity::reason) + sizeof(Identity::hello_seq) + sizeof(Identity::watchdog_ms) + sizeof(Identity::feedback_mode) + sizeof(Identity::feedback_hz) + sizeof(Identity::robot_name) == Identity::PAYLOAD_MAX, "IDENTITY member widths differ from the wire");
static_assert(sizeof(Identity) < 256, "IDENTITY member offsets must fit in a byte");
static_assert(Pong::PAYLOAD_MAX <= MAX_PAYLOAD, "PONG payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Pong::host_time_us) + sizeof(Pong::mcu_time_us) == Pong::PAYLOAD_MAX, "PONG member widths differ from the wire");
static_assert(sizeof(Pong) < 256, "PONG member offsets must fit in a byte");
static_assert(Ack::PAYLOAD_MAX <= MAX_PAYLOAD, "ACK payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Ack::req_id) + sizeof(Ack::req_seq) == Ack::PAYLOAD_MAX, "ACK member widths differ from the wire");
static_assert(sizeof(Ack) < 256, "ACK member offsets must fit in a byte");
static_assert(Nack::PAYLOAD_MAX <= MAX_PAYLOAD, "NACK payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Nack::req_id) + sizeof(Nack::req_seq) + sizeof(Nack::reason) + sizeof(Nack::detail) == Nack::PAYLOAD_MAX, "NACK member widths differ from the wire");
static_assert(sizeof(Nack) < 256, "NACK member offsets must fit in a byte");
static_assert(Pid::PAYLOAD_MAX <= MAX_PAYLOAD, "PID payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Pid::req_seq) + sizeof(Pid::wheel) + sizeof(Pid::kp) + sizeof(Pid::ki) + sizeof(Pid::kd) + sizeof(Pid::kf) == Pid::PAYLOAD_MAX, "PID member widths differ from the wire");
static_assert(sizeof(Pid) < 256, "PID member offsets must fit in a byte");
static_assert(Config::PAYLOAD_MAX <= MAX_PAYLOAD, "CONFIG payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Config::req_seq) + sizeof(Config::watchdog_ms) + sizeof(Config::safe_state) + sizeof(Config::accel_limit_mm_s2) + sizeof(Config::decel_limit_mm_s2) + sizeof(Config::max_wheel_speed_mm_s) + sizeof(Config::max_effort_permille) + sizeof(Config::encoder_cpr) + sizeof(Config::encoder_invert) + sizeof(Config::motor_invert) + sizeof(Config::wheel_diameter_um) + sizeof(Config::steering_center_cdeg) + sizeof(Config::steering_min_cdeg) + sizeof(Config::steering_max_cdeg) + sizeof(Config::steering_step_cdeg) + sizeof(Config::servo_min_us) + sizeof(Config::servo_max_us) + sizeof(Config::esc_min_us) + sizeof(Config::esc_neutral_us) + sizeof(Config::esc_max_us) + sizeof(Config::esc_arm_ms) + sizeof(Config::feedback_hz) == Config::PAYLOAD_MAX, "CONFIG member widths differ from the wire");
static_assert(sizeof(Config) < 256, "CONFIG member offsets must fit in a byte");
static_assert(LinkStats::PAYLOAD_MAX <= MAX_PAYLOAD, "LINK_STATS payload exceeds MAX_PAYLOAD");
static_assert(sizeof(LinkStats::req_seq) + sizeof(LinkStats::frames_ok) + sizeof(LinkStats::crc_errors) + sizeof(LinkStats::cobs_errors) + sizeof(LinkStats::length_errors) + sizeof(LinkStats::unknown_ids) + sizeof(LinkStats::value_errors) + sizeof(LinkStats::seq_gaps) + sizeof(LinkStats::bytes_discarded) + sizeof(LinkStats::rx_overruns) + sizeof(LinkStats::duplicates) + sizeof(LinkStats::frames_sent) == LinkStats::PAYLOAD_MAX, "LINK_STATS member widths differ from the wire");
static_assert(sizeof(LinkStats) < 256, "LINK_STATS member offsets must fit in a byte");
static_assert(Feedback::PAYLOAD_MAX <= MAX_PAYLOAD, "FEEDBACK payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Feedback::boot_id) + sizeof(Feedback::mcu_time_us) + sizeof(Feedback::tick) + sizeof(Feedback::ack_seq) + sizeof(Feedback::ack_tick) + sizeof(Feedback::status) + sizeof(Feedback::failsafe_reason) + sizeof(Feedback::encoder_counts) + sizeof(Feedback::wheel_speed_mm_s) + sizeof(Feedback::effort_permille) + sizeof(Feedback::steering_mrad) == Feedback::PAYLOAD_MAX, "FEEDBACK member widths differ from the wire");
static_assert(sizeof(Feedback) < 256, "FEEDBACK member offsets must fit in a byte");
static_assert(Log::PAYLOAD_MAX <= MAX_PAYLOAD, "LOG payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Log::level) + sizeof(Log::text) == Log::PAYLOAD_MAX, "LOG member widths differ from the wire");
static_assert(sizeof(Log) < 256, "LOG member offsets must fit in a byte");

// msg_id, CRC_EXTRA, PAYLOAD_SIZE, PAYLOAD_MAX of every message.
static const uint8_t MESSAGE_COUNT = 22;
static const uint8_t MESSAGES[MESSAGE_COUNT][4] ROVERLINK_PROGMEM = {
    {Hello::ID, Hello::CRC_EXTRA, Hello::PAYLOAD_SIZE, Hello::PAYLOAD_MAX},
    {Ping::ID, Ping::CRC_EXTRA, Ping::PAYLOAD_SIZE, Ping::PAYLOAD_MAX},
    {Arm::ID, Arm::CRC_EXTRA, Arm::PAYLOAD_SIZE, Arm::PAYLOAD_MAX},
    {Disarm::ID, Disarm::CRC_EXTRA, Disarm::PAYLOAD_SIZE, Disarm::PAYLOAD_MAX},
    {SetPid::ID, SetPid::CRC_EXTRA, SetPid::PAYLOAD_SIZE, SetPid::PAYLOAD_MAX},
    {GetPid::ID, GetPid::CRC_EXTRA, GetPid::PAYLOAD_SIZE, GetPid::PAYLOAD_MAX},
    {SetConfig::ID, SetConfig::CRC_EXTRA, SetConfig::PAYLOAD_SIZE, SetConfig::PAYLOAD_MAX},
    {GetConfig::ID, GetConfig::CRC_EXTRA, GetConfig::PAYLOAD_SIZE, GetConfig::PAYLOAD_MAX},
    {SaveConfig::ID, SaveConfig::CRC_EXTRA, SaveConfig::PAYLOAD_SIZE, SaveConfig::PAYLOAD_MAX},
    {ResetOdometry::ID, ResetOdometry::CRC_EXTRA, ResetOdometry::PAYLOAD_SIZE, ResetOdometry::PAYLOAD_MAX},
    {GetLinkStats::ID, GetLinkStats::CRC_EXTRA, GetLinkStats::PAYLOAD_SIZE, GetLinkStats::PAYLOAD_MAX},
    {SetWheelSpeeds::ID, SetWheelSpeeds::CRC_EXTRA, SetWheelSpeeds::PAYLOAD_SIZE, SetWheelSpeeds::PAYLOAD_MAX},
    {SetAckermann::ID, SetAckermann::CRC_EXTRA, SetAckermann::PAYLOAD_SIZE, SetAckermann::PAYLOAD_MAX},
    {Identity::ID, Identity::CRC_EXTRA, Identity::PAYLOAD_SIZE, Identity::PAYLOAD_MAX},
    {Pong::ID, Pong::CRC_EXTRA, Pong::PAYLOAD_SIZE, Pong::PAYLOAD_MAX},
    {Ack::ID, Ack::CRC_EXTRA, Ack::PAYLOAD_SIZE, Ack::PAYLOAD_MAX},
    {Nack::ID, Nack::CRC_EXTRA, Nack::PAYLOAD_SIZE, Nack::PAYLOAD_MAX},
    {Pid::ID, Pid::CRC_EXTRA, Pid::PAYLOAD_SIZE, Pid::PAYLOAD_MAX},
    {Config::ID, Config::CRC_EXTRA, Config::PAYLOAD_SIZE, Config::PAYLOAD_MAX},
    {LinkStats::ID, LinkStats::CRC_EXTRA, LinkStats::PAYLOAD_SIZE, LinkStats::PAYLOAD_MAX},
    {Feedback::ID, Feedback::CRC_EXTRA, Feedback::PAYLOAD_SIZE, Feedback::PAYLOAD_MAX},
    {Log::ID, Log::CRC_EXTRA, Log::PAYLOAD_SIZE, Log::PAYLOAD_MAX},
};

bool message_bounds(uint8_t msg_id, MessageBounds& out) {
    for (uint8_t i = 0; i < MESSAGE_COUNT; ++i) {
        const uint8_t* row = MESSAGES[i];
        if (ROVERLINK_READ_BYTE(row) == msg_id) {
            out.crc_extra = ROVERLINK_READ_BYTE(row + 1);
            out.min_payload = ROVERLINK_READ_BYTE(row + 2);
            out.max_payload = ROVERLINK_READ_BYTE(row + 3);
            return true;
        }
    }
    return false;
}

namespace {

// msg_id and layout (0: no fields) of every message one direction carries.
struct LayoutOf {
    uint8_t msg_id;
    const uint8_t* layout;
};

DispatchResult unpack_with(const LayoutOf* table, uint8_t count, uint8_t msg_id,
                           const uint8_t* payload, uint8_t len, void* m) {
    for (uint8_t i = 0; i < count; ++i) {
        if (ROVERLINK_READ_BYTE(&table[i].msg_id) == msg_id) {
            const uint8_t* layout = ROVERLINK_READ_PTR(&table[i].layout);
            const bool ok = layout != 0 ? layout::unpack(layout, payload, len, m) : len == 0;
            return ok ? DISPATCH_OK : DISPATCH_BAD_PAYLOAD;
        }
    }
    MessageBounds b;
    return message_bounds(msg_id, b) ? DISPATCH_WRONG_DIRECTION : DISPATCH_UNKNOWN_ID;
}

const LayoutOf HOST_TO_MCU[] ROVERLINK_PROGMEM = {
    {Hello::ID, HELLO_LAYOUT},
    {Ping::ID, PING_LAYOUT},
    {Arm::ID, ARM_LAYOUT},
    {Disarm::ID, 0},
    {SetPid::ID, SET_PID_LAYOUT},
    {GetPid::ID, GET_PID_LAYOUT},
    {SetConfig::ID, SET_CONFIG_LAYOUT},
    {GetConfig::ID, 0},
    {SaveConfig::ID, 0},
    {ResetOdometry::ID, 0},
    {GetLinkStats::ID, 0},
    {SetWheelSpeeds::ID, SET_WHEEL_SPEEDS_LAYOUT},
    {SetAckermann::ID, SET_ACKERMANN_LAYOUT},
};

const LayoutOf MCU_TO_HOST[] ROVERLINK_PROGMEM = {
    {Identity::ID, IDENTITY_LAYOUT},
    {Pong::ID, PONG_LAYOUT},
    {Ack::ID, ACK_LAYOUT},
    {Nack::ID, NACK_LAYOUT},
    {Pid::ID, PID_LAYOUT},
    {Config::ID, CONFIG_LAYOUT},
    {LinkStats::ID, LINK_STATS_LAYOUT},
    {Feedback::ID, FEEDBACK_LAYOUT},
    {Log::ID, LOG_LAYOUT},
};

}  // namespace

DispatchResult unpack_host_to_mcu(uint8_t msg_id, const uint8_t* payload, uint8_t len, HostToMcu& m) {
    return unpack_with(HOST_TO_MCU, sizeof HOST_TO_MCU / sizeof HOST_TO_MCU[0], msg_id, payload, len, &m);
}

DispatchResult unpack_mcu_to_host(uint8_t msg_id, const uint8_t* payload, uint8_t len, McuToHost& m) {
    return unpack_with(MCU_TO_HOST, sizeof MCU_TO_HOST / sizeof MCU_TO_HOST[0], msg_id, payload, len, &m);
}

// Layouts (codec/layout.h): PAYLOAD_SIZE, PAYLOAD_MAX, field count, then per field its code,
// its offset in the struct, [count | 0, max_len, offset of <name>_len], [check data, LE].
// HELLO: payload 9..9 bytes, 5 fields.
const uint8_t HELLO_LAYOUT[] ROVERLINK_PROGMEM = {
    9, 9, 5,
    layout::WIRE_U8, offsetof(Hello, protocol_version),  // 0 protocol_version
    layout::WIRE_U32, offsetof(Hello, spec_hash),  // 1 spec_hash
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Hello, watchdog_ms), 0x00, 0x00, 0x60, 0xEA,  // 2 watchdog_ms: 0..60000
    layout::WIRE_U8 | layout::CHECK_VALUES, offsetof(Hello, feedback_mode), 0x00, 0x01, 0x00,  // 3 feedback_mode: FeedbackMode 0..1
    layout::WIRE_U8, offsetof(Hello, feedback_hz),  // 4 feedback_hz
};

// PING: payload 4..4 bytes, 1 fields.
const uint8_t PING_LAYOUT[] ROVERLINK_PROGMEM = {
    4, 4, 1,
    layout::WIRE_U32, offsetof(Ping, host_time_us),  // 0 host_time_us
};

// ARM: payload 4..4 bytes, 1 fields.
const uint8_t ARM_LAYOUT[] ROVERLINK_PROGMEM = {
    4, 4, 1,
    layout::WIRE_U32, offsetof(Arm, boot_id),  // 0 boot_id
};

// SET_PID: payload 17..17 bytes, 5 fields.
const uint8_t SET_PID_LAYOUT[] ROVERLINK_PROGMEM = {
    17, 17, 5,
    layout::WIRE_U8, offsetof(SetPid, wheel),  // 0 wheel
    layout::WIRE_F32 | layout::CHECK_RANGE, offsetof(SetPid, kp), 0x00, 0x00, 0x00, 0x80, 0x00, 0x00, 0x7A, 0x44,  // 1 kp: 0.0f..1000.0f
    layout::WIRE_F32 | layout::CHECK_RANGE, offsetof(SetPid, ki), 0x00, 0x00, 0x00, 0x80, 0x00, 0x00, 0x7A, 0x44,  // 2 ki: 0.0f..1000.0f
    layout::WIRE_F32 | layout::CHECK_RANGE, offsetof(SetPid, kd), 0x00, 0x00, 0x00, 0x80, 0x00, 0x00, 0x7A, 0x44,  // 3 kd: 0.0f..1000.0f
    layout::WIRE_F32 | layout::CHECK_RANGE, offsetof(SetPid, kf), 0x00, 0x00, 0x00, 0x80, 0x00, 0x00, 0x7A, 0x44,  // 4 kf: 0.0f..1000.0f
};

// GET_PID: payload 1..1 bytes, 1 fields.
const uint8_t GET_PID_LAYOUT[] ROVERLINK_PROGMEM = {
    1, 1, 1,
    layout::WIRE_U8, offsetof(GetPid, wheel),  // 0 wheel
};

// SET_CONFIG: payload 40..40 bytes, 21 fields.
const uint8_t SET_CONFIG_LAYOUT[] ROVERLINK_PROGMEM = {
    40, 40, 21,
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, watchdog_ms), 0x32, 0x00, 0xD0, 0x07,  // 0 watchdog_ms: 50..2000
    layout::WIRE_U8 | layout::CHECK_VALUES, offsetof(SetConfig, safe_state), 0x00, 0x02, 0x00,  // 1 safe_state: SafeState 0..2
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, accel_limit_mm_s2), 0x01, 0x00, 0xFF, 0xFF,  // 2 accel_limit_mm_s2: 1..65535
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, decel_limit_mm_s2), 0x01, 0x00, 0xFF, 0xFF,  // 3 decel_limit_mm_s2: 1..65535
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, max_wheel_speed_mm_s), 0x01, 0x00, 0x20, 0x4E,  // 4 max_wheel_speed_mm_s: 1..20000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, max_effort_permille), 0x00, 0x00, 0xE8, 0x03,  // 5 max_effort_permille: 0..1000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, encoder_cpr), 0x01, 0x00, 0xFF, 0xFF,  // 6 encoder_cpr: 1..65535
    layout::WIRE_U8 | layout::CHECK_RANGE, offsetof(SetConfig, encoder_invert), 0x00, 0x03,  // 7 encoder_invert: 0..3
    layout::WIRE_U8 | layout::CHECK_RANGE, offsetof(SetConfig, motor_invert), 0x00, 0x03,  // 8 motor_invert: 0..3
    layout::WIRE_U32 | layout::CHECK_RANGE, offsetof(SetConfig, wheel_diameter_um), 0xE8, 0x03, 0x00, 0x00, 0x40, 0x42, 0x0F, 0x00,  // 9 wheel_diameter_um: 1000..1000000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, steering_center_cdeg), 0x00, 0x00, 0x50, 0x46,  // 10 steering_center_cdeg: 0..18000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, steering_min_cdeg), 0x00, 0x00, 0x50, 0x46,  // 11 steering_min_cdeg: 0..18000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, steering_max_cdeg), 0x00, 0x00, 0x50, 0x46,  // 12 steering_max_cdeg: 0..18000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, steering_step_cdeg), 0x00, 0x00, 0x28, 0x23,  // 13 steering_step_cdeg: 0..9000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, servo_min_us), 0x90, 0x01, 0x28, 0x0A,  // 14 servo_min_us: 400..2600
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, servo_max_us), 0x90, 0x01, 0x28, 0x0A,  // 15 servo_max_us: 400..2600
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, esc_min_us), 0x20, 0x03, 0x98, 0x08,  // 16 esc_min_us: 800..2200
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, esc_neutral_us), 0x20, 0x03, 0x98, 0x08,  // 17 esc_neutral_us: 800..2200
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, esc_max_us), 0x20, 0x03, 0x98, 0x08,  // 18 esc_max_us: 800..2200
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(SetConfig, esc_arm_ms), 0x00, 0x00, 0x10, 0x27,  // 19 esc_arm_ms: 0..10000
    layout::WIRE_U8 | layout::CHECK_RANGE, offsetof(SetConfig, feedback_hz), 0x01, 0x64,  // 20 feedback_hz: 1..100
};

// SET_WHEEL_SPEEDS: payload 4..4 bytes, 2 fields.
const uint8_t SET_WHEEL_SPEEDS_LAYOUT[] ROVERLINK_PROGMEM = {
    4, 4, 2,
    layout::WIRE_I16, offsetof(SetWheelSpeeds, left_mm_s),  // 0 left_mm_s
    layout::WIRE_I16, offsetof(SetWheelSpeeds, right_mm_s),  // 1 right_mm_s
};

// SET_ACKERMANN: payload 4..4 bytes, 2 fields.
const uint8_t SET_ACKERMANN_LAYOUT[] ROVERLINK_PROGMEM = {
    4, 4, 2,
    layout::WIRE_I16, offsetof(SetAckermann, speed_mm_s),  // 0 speed_mm_s
    layout::WIRE_I16 | layout::CHECK_RANGE, offsetof(SetAckermann, steering_mrad), 0xDD, 0xF9, 0x23, 0x06,  // 1 steering_mrad: -1571..1571
};

// IDENTITY: payload 25..49 bytes, 13 fields.
const uint8_t IDENTITY_LAYOUT[] ROVERLINK_PROGMEM = {
    25, 49, 13,
    layout::WIRE_U8, offsetof(Identity, protocol_version),  // 0 protocol_version
    layout::WIRE_U32, offsetof(Identity, spec_hash),  // 1 spec_hash
    layout::WIRE_U8 | layout::ARRAY, offsetof(Identity, firmware_version), 3,  // 2 firmware_version
    layout::WIRE_U8 | layout::CHECK_VALUES, offsetof(Identity, board), 0x00, 0x04, 0x00,  // 3 board: Board 0..4
    layout::WIRE_U16 | layout::CHECK_FLAGS, offsetof(Identity, capabilities), 0xFF, 0x00,  // 4 capabilities: Capability bits 0xFF
    layout::WIRE_U32, offsetof(Identity, boot_id),  // 5 boot_id
    layout::WIRE_U32, offsetof(Identity, uptime_ms),  // 6 uptime_ms
    layout::WIRE_U8 | layout::CHECK_VALUES, offsetof(Identity, reason), 0x00, 0x02, 0x00,  // 7 reason: IdentityReason 0..2
    layout::WIRE_U8, offsetof(Identity, hello_seq),  // 8 hello_seq
    layout::WIRE_U16, offsetof(Identity, watchdog_ms),  // 9 watchdog_ms
    layout::WIRE_U8 | layout::CHECK_VALUES, offsetof(Identity, feedback_mode), 0x00, 0x01, 0x00,  // 10 feedback_mode: FeedbackMode 0..1
    layout::WIRE_U8, offsetof(Identity, feedback_hz),  // 11 feedback_hz
    layout::WIRE_U8 | layout::CHECK_VALUES | layout::ARRAY, offsetof(Identity, robot_name), 0, 24, offsetof(Identity, robot_name_len), 0x00, 0x7F, 0x00,  // 12 robot_name: ASCII
};

// PONG: payload 8..8 bytes, 2 fields.
const uint8_t PONG_LAYOUT[] ROVERLINK_PROGMEM = {
    8, 8, 2,
    layout::WIRE_U32, offsetof(Pong, host_time_us),  // 0 host_time_us
    layout::WIRE_U32, offsetof(Pong, mcu_time_us),  // 1 mcu_time_us
};

// ACK: payload 2..2 bytes, 2 fields.
const uint8_t ACK_LAYOUT[] ROVERLINK_PROGMEM = {
    2, 2, 2,
    layout::WIRE_U8, offsetof(Ack, req_id),  // 0 req_id
    layout::WIRE_U8, offsetof(Ack, req_seq),  // 1 req_seq
};

// NACK: payload 4..4 bytes, 4 fields.
const uint8_t NACK_LAYOUT[] ROVERLINK_PROGMEM = {
    4, 4, 4,
    layout::WIRE_U8, offsetof(Nack, req_id),  // 0 req_id
    layout::WIRE_U8, offsetof(Nack, req_seq),  // 1 req_seq
    layout::WIRE_U8 | layout::CHECK_VALUES, offsetof(Nack, reason), 0x01, 0x09, 0x00,  // 2 reason: NackReason 1..9
    layout::WIRE_U8, offsetof(Nack, detail),  // 3 detail
};

// PID: payload 18..18 bytes, 6 fields.
const uint8_t PID_LAYOUT[] ROVERLINK_PROGMEM = {
    18, 18, 6,
    layout::WIRE_U8, offsetof(Pid, req_seq),  // 0 req_seq
    layout::WIRE_U8, offsetof(Pid, wheel),  // 1 wheel
    layout::WIRE_F32 | layout::CHECK_RANGE, offsetof(Pid, kp), 0x00, 0x00, 0x00, 0x80, 0x00, 0x00, 0x7A, 0x44,  // 2 kp: 0.0f..1000.0f
    layout::WIRE_F32 | layout::CHECK_RANGE, offsetof(Pid, ki), 0x00, 0x00, 0x00, 0x80, 0x00, 0x00, 0x7A, 0x44,  // 3 ki: 0.0f..1000.0f
    layout::WIRE_F32 | layout::CHECK_RANGE, offsetof(Pid, kd), 0x00, 0x00, 0x00, 0x80, 0x00, 0x00, 0x7A, 0x44,  // 4 kd: 0.0f..1000.0f
    layout::WIRE_F32 | layout::CHECK_RANGE, offsetof(Pid, kf), 0x00, 0x00, 0x00, 0x80, 0x00, 0x00, 0x7A, 0x44,  // 5 kf: 0.0f..1000.0f
};

// CONFIG: payload 41..41 bytes, 22 fields.
const uint8_t CONFIG_LAYOUT[] ROVERLINK_PROGMEM = {
    41, 41, 22,
    layout::WIRE_U8, offsetof(Config, req_seq),  // 0 req_seq
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, watchdog_ms), 0x32, 0x00, 0xD0, 0x07,  // 1 watchdog_ms: 50..2000
    layout::WIRE_U8 | layout::CHECK_VALUES, offsetof(Config, safe_state), 0x00, 0x02, 0x00,  // 2 safe_state: SafeState 0..2
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, accel_limit_mm_s2), 0x01, 0x00, 0xFF, 0xFF,  // 3 accel_limit_mm_s2: 1..65535
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, decel_limit_mm_s2), 0x01, 0x00, 0xFF, 0xFF,  // 4 decel_limit_mm_s2: 1..65535
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, max_wheel_speed_mm_s), 0x01, 0x00, 0x20, 0x4E,  // 5 max_wheel_speed_mm_s: 1..20000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, max_effort_permille), 0x00, 0x00, 0xE8, 0x03,  // 6 max_effort_permille: 0..1000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, encoder_cpr), 0x01, 0x00, 0xFF, 0xFF,  // 7 encoder_cpr: 1..65535
    layout::WIRE_U8 | layout::CHECK_RANGE, offsetof(Config, encoder_invert), 0x00, 0x03,  // 8 encoder_invert: 0..3
    layout::WIRE_U8 | layout::CHECK_RANGE, offsetof(Config, motor_invert), 0x00, 0x03,  // 9 motor_invert: 0..3
    layout::WIRE_U32 | layout::CHECK_RANGE, offsetof(Config, wheel_diameter_um), 0xE8, 0x03, 0x00, 0x00, 0x40, 0x42, 0x0F, 0x00,  // 10 wheel_diameter_um: 1000..1000000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, steering_center_cdeg), 0x00, 0x00, 0x50, 0x46,  // 11 steering_center_cdeg: 0..18000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, steering_min_cdeg), 0x00, 0x00, 0x50, 0x46,  // 12 steering_min_cdeg: 0..18000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, steering_max_cdeg), 0x00, 0x00, 0x50, 0x46,  // 13 steering_max_cdeg: 0..18000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, steering_step_cdeg), 0x00, 0x00, 0x28, 0x23,  // 14 steering_step_cdeg: 0..9000
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, servo_min_us), 0x90, 0x01, 0x28, 0x0A,  // 15 servo_min_us: 400..2600
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, servo_max_us), 0x90, 0x01, 0x28, 0x0A,  // 16 servo_max_us: 400..2600
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, esc_min_us), 0x20, 0x03, 0x98, 0x08,  // 17 esc_min_us: 800..2200
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, esc_neutral_us), 0x20, 0x03, 0x98, 0x08,  // 18 esc_neutral_us: 800..2200
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, esc_max_us), 0x20, 0x03, 0x98, 0x08,  // 19 esc_max_us: 800..2200
    layout::WIRE_U16 | layout::CHECK_RANGE, offsetof(Config, esc_arm_ms), 0x00, 0x00, 0x10, 0x27,  // 20 esc_arm_ms: 0..10000
    layout::WIRE_U8 | layout::CHECK_RANGE, offsetof(Config, feedback_hz), 0x01, 0x64,  // 21 feedback_hz: 1..100
};

// LINK_STATS: payload 45..45 bytes, 12 fields.
const uint8_t LINK_STATS_LAYOUT[] ROVERLINK_PROGMEM = {
    45, 45, 12,
    layout::WIRE_U8, offsetof(LinkStats, req_seq),  // 0 req_seq
    layout::WIRE_U32, offsetof(LinkStats, frames_ok),  // 1 frames_ok
    layout::WIRE_U32, offsetof(LinkStats, crc_errors),  // 2 crc_errors
    layout::WIRE_U32, offsetof(LinkStats, cobs_errors),  // 3 cobs_errors
    layout::WIRE_U32, offsetof(LinkStats, length_errors),  // 4 length_errors
    layout::WIRE_U32, offsetof(LinkStats, unknown_ids),  // 5 unknown_ids
    layout::WIRE_U32, offsetof(LinkStats, value_errors),  // 6 value_errors
    layout::WIRE_U32, offsetof(LinkStats, seq_gaps),  // 7 seq_gaps
    layout::WIRE_U32, offsetof(LinkStats, bytes_discarded),  // 8 bytes_discarded
    layout::WIRE_U32, offsetof(LinkStats, rx_overruns),  // 9 rx_overruns
    layout::WIRE_U32, offsetof(LinkStats, duplicates),  // 10 duplicates
    layout::WIRE_U32, offsetof(LinkStats, frames_sent),  // 11 frames_sent
};

// FEEDBACK: payload 33..33 bytes, 11 fields.
const uint8_t FEEDBACK_LAYOUT[] ROVERLINK_PROGMEM = {
    33, 33, 11,
    layout::WIRE_U32, offsetof(Feedback, boot_id),  // 0 boot_id
    layout::WIRE_U32, offsetof(Feedback, mcu_time_us),  // 1 mcu_time_us
    layout::WIRE_U16, offsetof(Feedback, tick),  // 2 tick
    layout::WIRE_U8, offsetof(Feedback, ack_seq),  // 3 ack_seq
    layout::WIRE_U16, offsetof(Feedback, ack_tick),  // 4 ack_tick
    layout::WIRE_U8 | layout::CHECK_FLAGS, offsetof(Feedback, status), 0x7F,  // 5 status: Status bits 0x7F
    layout::WIRE_U8 | layout::CHECK_VALUES, offsetof(Feedback, failsafe_reason), 0x00, 0x04, 0x00,  // 6 failsafe_reason: FailsafeReason 0..4
    layout::WIRE_I32 | layout::ARRAY, offsetof(Feedback, encoder_counts), 2,  // 7 encoder_counts
    layout::WIRE_I16 | layout::ARRAY, offsetof(Feedback, wheel_speed_mm_s), 2,  // 8 wheel_speed_mm_s
    layout::WIRE_I16 | layout::CHECK_RANGE | layout::ARRAY, offsetof(Feedback, effort_permille), 2, 0x18, 0xFC, 0xE8, 0x03,  // 9 effort_permille: -1000..1000
    layout::WIRE_I16 | layout::CHECK_RANGE, offsetof(Feedback, steering_mrad), 0xDD, 0xF9, 0x23, 0x06,  // 10 steering_mrad: -1571..1571
};

// LOG: payload 1..61 bytes, 2 fields.
const uint8_t LOG_LAYOUT[] ROVERLINK_PROGMEM = {
    1, 61, 2,
    layout::WIRE_U8 | layout::CHECK_VALUES, offsetof(Log, level), 0x00, 0x03, 0x00,  // 0 level: LogLevel 0..3
    layout::WIRE_U8 | layout::CHECK_VALUES | layout::ARRAY, offsetof(Log, text), 0, 60, offsetof(Log, text_len), 0x00, 0x7F, 0x00,  // 1 text: ASCII
};

const uint8_t TRANSITIONS[TRANSITION_COUNT][6] ROVERLINK_PROGMEM = {
    {0x01, 0, GUARD_NONE, 1, 0x09, 0x00},  // BOOT INIT_DONE -> IDLE
    {0x02, 1, 1, 2, 0x02, 0x00},  // IDLE HELLO [compatible] -> DISARMED
    {0x02, 1, 1 | GUARD_NEGATED, 1, 0x04, 0x00},  // IDLE HELLO [!compatible] -> IDLE
    {0x1C, 1, 1, 2, 0x8A, 0x00},  // DISARMED|ARMED|FAILSAFE HELLO [compatible] -> DISARMED
    {0x1C, 1, 1 | GUARD_NEGATED, 1, 0x8C, 0x00},  // DISARMED|ARMED|FAILSAFE HELLO [!compatible] -> IDLE
    {0x02, 2, GUARD_NONE, 1, 0x00, 0x02},  // IDLE ARM -> IDLE
    {0x14, 2, 2, 3, 0xB0, 0x01},  // DISARMED|FAILSAFE ARM [boot_id_matches] -> ARMED
    {0x08, 2, 2, 3, 0x20, 0x01},  // ARMED ARM [boot_id_matches] -> ARMED
    {0x1C, 2, 2 | GUARD_NEGATED, TARGET_STAY, 0x00, 0x02},  // DISARMED|ARMED|FAILSAFE ARM [!boot_id_matches] -> (stay)
    {0x02, 3, GUARD_NONE, 1, 0x00, 0x01},  // IDLE DISARM -> IDLE
    {0x1C, 3, GUARD_NONE, 2, 0x88, 0x01},  // DISARMED|ARMED|FAILSAFE DISARM -> DISARMED
    {0x08, 4, GUARD_NONE, 3, 0x00, 0x04},  // ARMED SETPOINT -> ARMED
    {0x16, 4, GUARD_NONE, TARGET_STAY, 0x00, 0x02},  // IDLE|DISARMED|FAILSAFE SETPOINT -> (stay)
    {0x1C, 5, GUARD_NONE, TARGET_STAY, 0x20, 0x00},  // DISARMED|ARMED|FAILSAFE VALID_FRAME -> (stay)
    {0x08, 6, GUARD_NONE, 4, 0x48, 0x00},  // ARMED WATCHDOG_EXPIRED -> FAILSAFE
    {0x0C, 7, GUARD_NONE, 4, 0x48, 0x00},  // ARMED|DISARMED FAULT -> FAILSAFE
    {0x1F, 8, GUARD_NONE, 0, 0x08, 0x00},  // BOOT|IDLE|DISARMED|ARMED|FAILSAFE RESET -> BOOT
};

}  // namespace proto
}  // namespace roverlink
