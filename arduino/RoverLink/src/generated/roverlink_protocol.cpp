// DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
// spec hash: 0x163FE6FE
#include "roverlink_protocol.h"

#include "../codec/wire.h"

namespace roverlink {
namespace proto {

// Every struct member has the width of its wire field (no int, no double; AVR and ARM agree).
static_assert(Hello::PAYLOAD_MAX <= MAX_PAYLOAD, "HELLO payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Hello::protocol_version) + sizeof(Hello::spec_hash) + sizeof(Hello::watchdog_ms) + sizeof(Hello::feedback_mode) + sizeof(Hello::feedback_hz) == Hello::PAYLOAD_MAX, "HELLO member widths differ from the wire");
static_assert(Ping::PAYLOAD_MAX <= MAX_PAYLOAD, "PING payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Ping::host_time_us) == Ping::PAYLOAD_MAX, "PING member widths differ from the wire");
static_assert(Arm::PAYLOAD_MAX <= MAX_PAYLOAD, "ARM payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Arm::boot_id) == Arm::PAYLOAD_MAX, "ARM member widths differ from the wire");
static_assert(Disarm::PAYLOAD_MAX <= MAX_PAYLOAD, "DISARM payload exceeds MAX_PAYLOAD");
static_assert(SetPid::PAYLOAD_MAX <= MAX_PAYLOAD, "SET_PID payload exceeds MAX_PAYLOAD");
static_assert(sizeof(SetPid::wheel) + sizeof(SetPid::kp) + sizeof(SetPid::ki) + sizeof(SetPid::kd) + sizeof(SetPid::kf) == SetPid::PAYLOAD_MAX, "SET_PID member widths differ from the wire");
static_assert(GetPid::PAYLOAD_MAX <= MAX_PAYLOAD, "GET_PID payload exceeds MAX_PAYLOAD");
static_assert(sizeof(GetPid::wheel) == GetPid::PAYLOAD_MAX, "GET_PID member widths differ from the wire");
static_assert(SetConfig::PAYLOAD_MAX <= MAX_PAYLOAD, "SET_CONFIG payload exceeds MAX_PAYLOAD");
static_assert(sizeof(SetConfig::watchdog_ms) + sizeof(SetConfig::safe_state) + sizeof(SetConfig::accel_limit_mm_s2) + sizeof(SetConfig::decel_limit_mm_s2) + sizeof(SetConfig::max_wheel_speed_mm_s) + sizeof(SetConfig::max_effort_permille) + sizeof(SetConfig::encoder_cpr) + sizeof(SetConfig::encoder_invert) + sizeof(SetConfig::motor_invert) + sizeof(SetConfig::wheel_diameter_um) + sizeof(SetConfig::steering_center_cdeg) + sizeof(SetConfig::steering_min_cdeg) + sizeof(SetConfig::steering_max_cdeg) + sizeof(SetConfig::steering_step_cdeg) + sizeof(SetConfig::servo_min_us) + sizeof(SetConfig::servo_max_us) + sizeof(SetConfig::esc_min_us) + sizeof(SetConfig::esc_neutral_us) + sizeof(SetConfig::esc_max_us) + sizeof(SetConfig::esc_arm_ms) + sizeof(SetConfig::feedback_hz) == SetConfig::PAYLOAD_MAX, "SET_CONFIG member widths differ from the wire");
static_assert(GetConfig::PAYLOAD_MAX <= MAX_PAYLOAD, "GET_CONFIG payload exceeds MAX_PAYLOAD");
static_assert(SaveConfig::PAYLOAD_MAX <= MAX_PAYLOAD, "SAVE_CONFIG payload exceeds MAX_PAYLOAD");
static_assert(ResetOdometry::PAYLOAD_MAX <= MAX_PAYLOAD, "RESET_ODOMETRY payload exceeds MAX_PAYLOAD");
static_assert(GetLinkStats::PAYLOAD_MAX <= MAX_PAYLOAD, "GET_LINK_STATS payload exceeds MAX_PAYLOAD");
static_assert(SetWheelSpeeds::PAYLOAD_MAX <= MAX_PAYLOAD, "SET_WHEEL_SPEEDS payload exceeds MAX_PAYLOAD");
static_assert(sizeof(SetWheelSpeeds::left_mm_s) + sizeof(SetWheelSpeeds::right_mm_s) == SetWheelSpeeds::PAYLOAD_MAX, "SET_WHEEL_SPEEDS member widths differ from the wire");
static_assert(SetAckermann::PAYLOAD_MAX <= MAX_PAYLOAD, "SET_ACKERMANN payload exceeds MAX_PAYLOAD");
static_assert(sizeof(SetAckermann::speed_mm_s) + sizeof(SetAckermann::steering_mrad) == SetAckermann::PAYLOAD_MAX, "SET_ACKERMANN member widths differ from the wire");
static_assert(Identity::PAYLOAD_MAX <= MAX_PAYLOAD, "IDENTITY payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Identity::protocol_version) + sizeof(Identity::spec_hash) + sizeof(Identity::firmware_version) + sizeof(Identity::board) + sizeof(Identity::capabilities) + sizeof(Identity::boot_id) + sizeof(Identity::uptime_ms) + sizeof(Identity::reason) + sizeof(Identity::hello_seq) + sizeof(Identity::watchdog_ms) + sizeof(Identity::feedback_mode) + sizeof(Identity::feedback_hz) + sizeof(Identity::robot_name) == Identity::PAYLOAD_MAX, "IDENTITY member widths differ from the wire");
static_assert(Pong::PAYLOAD_MAX <= MAX_PAYLOAD, "PONG payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Pong::host_time_us) + sizeof(Pong::mcu_time_us) == Pong::PAYLOAD_MAX, "PONG member widths differ from the wire");
static_assert(Ack::PAYLOAD_MAX <= MAX_PAYLOAD, "ACK payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Ack::req_id) + sizeof(Ack::req_seq) == Ack::PAYLOAD_MAX, "ACK member widths differ from the wire");
static_assert(Nack::PAYLOAD_MAX <= MAX_PAYLOAD, "NACK payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Nack::req_id) + sizeof(Nack::req_seq) + sizeof(Nack::reason) + sizeof(Nack::detail) == Nack::PAYLOAD_MAX, "NACK member widths differ from the wire");
static_assert(Pid::PAYLOAD_MAX <= MAX_PAYLOAD, "PID payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Pid::req_seq) + sizeof(Pid::wheel) + sizeof(Pid::kp) + sizeof(Pid::ki) + sizeof(Pid::kd) + sizeof(Pid::kf) == Pid::PAYLOAD_MAX, "PID member widths differ from the wire");
static_assert(Config::PAYLOAD_MAX <= MAX_PAYLOAD, "CONFIG payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Config::req_seq) + sizeof(Config::watchdog_ms) + sizeof(Config::safe_state) + sizeof(Config::accel_limit_mm_s2) + sizeof(Config::decel_limit_mm_s2) + sizeof(Config::max_wheel_speed_mm_s) + sizeof(Config::max_effort_permille) + sizeof(Config::encoder_cpr) + sizeof(Config::encoder_invert) + sizeof(Config::motor_invert) + sizeof(Config::wheel_diameter_um) + sizeof(Config::steering_center_cdeg) + sizeof(Config::steering_min_cdeg) + sizeof(Config::steering_max_cdeg) + sizeof(Config::steering_step_cdeg) + sizeof(Config::servo_min_us) + sizeof(Config::servo_max_us) + sizeof(Config::esc_min_us) + sizeof(Config::esc_neutral_us) + sizeof(Config::esc_max_us) + sizeof(Config::esc_arm_ms) + sizeof(Config::feedback_hz) == Config::PAYLOAD_MAX, "CONFIG member widths differ from the wire");
static_assert(LinkStats::PAYLOAD_MAX <= MAX_PAYLOAD, "LINK_STATS payload exceeds MAX_PAYLOAD");
static_assert(sizeof(LinkStats::req_seq) + sizeof(LinkStats::frames_ok) + sizeof(LinkStats::crc_errors) + sizeof(LinkStats::cobs_errors) + sizeof(LinkStats::length_errors) + sizeof(LinkStats::unknown_ids) + sizeof(LinkStats::value_errors) + sizeof(LinkStats::seq_gaps) + sizeof(LinkStats::bytes_discarded) + sizeof(LinkStats::rx_overruns) + sizeof(LinkStats::duplicates) + sizeof(LinkStats::frames_sent) == LinkStats::PAYLOAD_MAX, "LINK_STATS member widths differ from the wire");
static_assert(Feedback::PAYLOAD_MAX <= MAX_PAYLOAD, "FEEDBACK payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Feedback::boot_id) + sizeof(Feedback::mcu_time_us) + sizeof(Feedback::tick) + sizeof(Feedback::ack_seq) + sizeof(Feedback::ack_tick) + sizeof(Feedback::status) + sizeof(Feedback::failsafe_reason) + sizeof(Feedback::encoder_counts) + sizeof(Feedback::wheel_speed_mm_s) + sizeof(Feedback::effort_permille) + sizeof(Feedback::steering_mrad) == Feedback::PAYLOAD_MAX, "FEEDBACK member widths differ from the wire");
static_assert(Log::PAYLOAD_MAX <= MAX_PAYLOAD, "LOG payload exceeds MAX_PAYLOAD");
static_assert(sizeof(Log::level) + sizeof(Log::text) == Log::PAYLOAD_MAX, "LOG member widths differ from the wire");

bool is_valid_Board(uint8_t value) {
    switch (value) {
    case 0:
    case 1:
    case 2:
    case 3:
    case 4:
        return true;
    default:
        return false;
    }
}

bool is_valid_FeedbackMode(uint8_t value) {
    switch (value) {
    case 0:
    case 1:
        return true;
    default:
        return false;
    }
}

bool is_valid_SafeState(uint8_t value) {
    switch (value) {
    case 0:
    case 1:
    case 2:
        return true;
    default:
        return false;
    }
}

bool is_valid_FailsafeReason(uint8_t value) {
    switch (value) {
    case 0:
    case 1:
    case 2:
    case 3:
    case 4:
        return true;
    default:
        return false;
    }
}

bool is_valid_NackReason(uint8_t value) {
    switch (value) {
    case 1:
    case 2:
    case 3:
    case 4:
    case 5:
    case 6:
    case 7:
    case 8:
    case 9:
        return true;
    default:
        return false;
    }
}

bool is_valid_IdentityReason(uint8_t value) {
    switch (value) {
    case 0:
    case 1:
    case 2:
        return true;
    default:
        return false;
    }
}

bool is_valid_LogLevel(uint8_t value) {
    switch (value) {
    case 0:
    case 1:
    case 2:
    case 3:
        return true;
    default:
        return false;
    }
}

bool message_bounds(uint8_t msg_id, MessageBounds& out) {
    switch (msg_id) {
    case Hello::ID:
        out.crc_extra = Hello::CRC_EXTRA;
        out.min_payload = Hello::PAYLOAD_SIZE;
        out.max_payload = Hello::PAYLOAD_MAX;
        return true;
    case Ping::ID:
        out.crc_extra = Ping::CRC_EXTRA;
        out.min_payload = Ping::PAYLOAD_SIZE;
        out.max_payload = Ping::PAYLOAD_MAX;
        return true;
    case Arm::ID:
        out.crc_extra = Arm::CRC_EXTRA;
        out.min_payload = Arm::PAYLOAD_SIZE;
        out.max_payload = Arm::PAYLOAD_MAX;
        return true;
    case Disarm::ID:
        out.crc_extra = Disarm::CRC_EXTRA;
        out.min_payload = Disarm::PAYLOAD_SIZE;
        out.max_payload = Disarm::PAYLOAD_MAX;
        return true;
    case SetPid::ID:
        out.crc_extra = SetPid::CRC_EXTRA;
        out.min_payload = SetPid::PAYLOAD_SIZE;
        out.max_payload = SetPid::PAYLOAD_MAX;
        return true;
    case GetPid::ID:
        out.crc_extra = GetPid::CRC_EXTRA;
        out.min_payload = GetPid::PAYLOAD_SIZE;
        out.max_payload = GetPid::PAYLOAD_MAX;
        return true;
    case SetConfig::ID:
        out.crc_extra = SetConfig::CRC_EXTRA;
        out.min_payload = SetConfig::PAYLOAD_SIZE;
        out.max_payload = SetConfig::PAYLOAD_MAX;
        return true;
    case GetConfig::ID:
        out.crc_extra = GetConfig::CRC_EXTRA;
        out.min_payload = GetConfig::PAYLOAD_SIZE;
        out.max_payload = GetConfig::PAYLOAD_MAX;
        return true;
    case SaveConfig::ID:
        out.crc_extra = SaveConfig::CRC_EXTRA;
        out.min_payload = SaveConfig::PAYLOAD_SIZE;
        out.max_payload = SaveConfig::PAYLOAD_MAX;
        return true;
    case ResetOdometry::ID:
        out.crc_extra = ResetOdometry::CRC_EXTRA;
        out.min_payload = ResetOdometry::PAYLOAD_SIZE;
        out.max_payload = ResetOdometry::PAYLOAD_MAX;
        return true;
    case GetLinkStats::ID:
        out.crc_extra = GetLinkStats::CRC_EXTRA;
        out.min_payload = GetLinkStats::PAYLOAD_SIZE;
        out.max_payload = GetLinkStats::PAYLOAD_MAX;
        return true;
    case SetWheelSpeeds::ID:
        out.crc_extra = SetWheelSpeeds::CRC_EXTRA;
        out.min_payload = SetWheelSpeeds::PAYLOAD_SIZE;
        out.max_payload = SetWheelSpeeds::PAYLOAD_MAX;
        return true;
    case SetAckermann::ID:
        out.crc_extra = SetAckermann::CRC_EXTRA;
        out.min_payload = SetAckermann::PAYLOAD_SIZE;
        out.max_payload = SetAckermann::PAYLOAD_MAX;
        return true;
    case Identity::ID:
        out.crc_extra = Identity::CRC_EXTRA;
        out.min_payload = Identity::PAYLOAD_SIZE;
        out.max_payload = Identity::PAYLOAD_MAX;
        return true;
    case Pong::ID:
        out.crc_extra = Pong::CRC_EXTRA;
        out.min_payload = Pong::PAYLOAD_SIZE;
        out.max_payload = Pong::PAYLOAD_MAX;
        return true;
    case Ack::ID:
        out.crc_extra = Ack::CRC_EXTRA;
        out.min_payload = Ack::PAYLOAD_SIZE;
        out.max_payload = Ack::PAYLOAD_MAX;
        return true;
    case Nack::ID:
        out.crc_extra = Nack::CRC_EXTRA;
        out.min_payload = Nack::PAYLOAD_SIZE;
        out.max_payload = Nack::PAYLOAD_MAX;
        return true;
    case Pid::ID:
        out.crc_extra = Pid::CRC_EXTRA;
        out.min_payload = Pid::PAYLOAD_SIZE;
        out.max_payload = Pid::PAYLOAD_MAX;
        return true;
    case Config::ID:
        out.crc_extra = Config::CRC_EXTRA;
        out.min_payload = Config::PAYLOAD_SIZE;
        out.max_payload = Config::PAYLOAD_MAX;
        return true;
    case LinkStats::ID:
        out.crc_extra = LinkStats::CRC_EXTRA;
        out.min_payload = LinkStats::PAYLOAD_SIZE;
        out.max_payload = LinkStats::PAYLOAD_MAX;
        return true;
    case Feedback::ID:
        out.crc_extra = Feedback::CRC_EXTRA;
        out.min_payload = Feedback::PAYLOAD_SIZE;
        out.max_payload = Feedback::PAYLOAD_MAX;
        return true;
    case Log::ID:
        out.crc_extra = Log::CRC_EXTRA;
        out.min_payload = Log::PAYLOAD_SIZE;
        out.max_payload = Log::PAYLOAD_MAX;
        return true;
    default:
        return false;
    }
}

uint8_t pack(const Hello& m, uint8_t* payload) {
    payload[0] = m.protocol_version;
    wire::put_u32(payload + 1, m.spec_hash);
    wire::put_u16(payload + 5, m.watchdog_ms);
    payload[7] = static_cast<uint8_t>(m.feedback_mode);
    payload[8] = m.feedback_hz;
    return 9;
}

bool unpack(const uint8_t* payload, uint8_t len, Hello& m) {
    if (len != 9) return false;
    m.protocol_version = payload[0];
    m.spec_hash = wire::get_u32(payload + 1);
    m.watchdog_ms = wire::get_u16(payload + 5);
    if (!is_valid_FeedbackMode(payload[7])) return false;
    m.feedback_mode = static_cast<FeedbackMode>(payload[7]);
    m.feedback_hz = payload[8];
    return true;
}

uint8_t check_ranges(const Hello& m) {
    if (m.watchdog_ms > 60000) return 2;
    return ALL_FIELDS_VALID;
}

uint8_t pack(const Ping& m, uint8_t* payload) {
    wire::put_u32(payload + 0, m.host_time_us);
    return 4;
}

bool unpack(const uint8_t* payload, uint8_t len, Ping& m) {
    if (len != 4) return false;
    m.host_time_us = wire::get_u32(payload + 0);
    return true;
}

uint8_t check_ranges(const Ping& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const Arm& m, uint8_t* payload) {
    wire::put_u32(payload + 0, m.boot_id);
    return 4;
}

bool unpack(const uint8_t* payload, uint8_t len, Arm& m) {
    if (len != 4) return false;
    m.boot_id = wire::get_u32(payload + 0);
    return true;
}

uint8_t check_ranges(const Arm& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const Disarm& /*m*/, uint8_t* payload) {
    (void)payload;
    return 0;
}

bool unpack(const uint8_t* /*payload*/, uint8_t len, Disarm& /*m*/) {
    if (len != 0) return false;
    return true;
}

uint8_t check_ranges(const Disarm& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const SetPid& m, uint8_t* payload) {
    payload[0] = m.wheel;
    wire::put_f32(payload + 1, m.kp);
    wire::put_f32(payload + 5, m.ki);
    wire::put_f32(payload + 9, m.kd);
    wire::put_f32(payload + 13, m.kf);
    return 17;
}

bool unpack(const uint8_t* payload, uint8_t len, SetPid& m) {
    if (len != 17) return false;
    m.wheel = payload[0];
    m.kp = wire::get_f32(payload + 1);
    m.ki = wire::get_f32(payload + 5);
    m.kd = wire::get_f32(payload + 9);
    m.kf = wire::get_f32(payload + 13);
    return true;
}

uint8_t check_ranges(const SetPid& m) {
    if (!(m.kp >= 0.0f && m.kp <= 1000.0f)) return 1;
    if (!(m.ki >= 0.0f && m.ki <= 1000.0f)) return 2;
    if (!(m.kd >= 0.0f && m.kd <= 1000.0f)) return 3;
    if (!(m.kf >= 0.0f && m.kf <= 1000.0f)) return 4;
    return ALL_FIELDS_VALID;
}

uint8_t pack(const GetPid& m, uint8_t* payload) {
    payload[0] = m.wheel;
    return 1;
}

bool unpack(const uint8_t* payload, uint8_t len, GetPid& m) {
    if (len != 1) return false;
    m.wheel = payload[0];
    return true;
}

uint8_t check_ranges(const GetPid& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const SetConfig& m, uint8_t* payload) {
    wire::put_u16(payload + 0, m.watchdog_ms);
    payload[2] = static_cast<uint8_t>(m.safe_state);
    wire::put_u16(payload + 3, m.accel_limit_mm_s2);
    wire::put_u16(payload + 5, m.decel_limit_mm_s2);
    wire::put_u16(payload + 7, m.max_wheel_speed_mm_s);
    wire::put_u16(payload + 9, m.max_effort_permille);
    wire::put_u16(payload + 11, m.encoder_cpr);
    payload[13] = m.encoder_invert;
    payload[14] = m.motor_invert;
    wire::put_u32(payload + 15, m.wheel_diameter_um);
    wire::put_u16(payload + 19, m.steering_center_cdeg);
    wire::put_u16(payload + 21, m.steering_min_cdeg);
    wire::put_u16(payload + 23, m.steering_max_cdeg);
    wire::put_u16(payload + 25, m.steering_step_cdeg);
    wire::put_u16(payload + 27, m.servo_min_us);
    wire::put_u16(payload + 29, m.servo_max_us);
    wire::put_u16(payload + 31, m.esc_min_us);
    wire::put_u16(payload + 33, m.esc_neutral_us);
    wire::put_u16(payload + 35, m.esc_max_us);
    wire::put_u16(payload + 37, m.esc_arm_ms);
    payload[39] = m.feedback_hz;
    return 40;
}

bool unpack(const uint8_t* payload, uint8_t len, SetConfig& m) {
    if (len != 40) return false;
    m.watchdog_ms = wire::get_u16(payload + 0);
    if (!is_valid_SafeState(payload[2])) return false;
    m.safe_state = static_cast<SafeState>(payload[2]);
    m.accel_limit_mm_s2 = wire::get_u16(payload + 3);
    m.decel_limit_mm_s2 = wire::get_u16(payload + 5);
    m.max_wheel_speed_mm_s = wire::get_u16(payload + 7);
    m.max_effort_permille = wire::get_u16(payload + 9);
    m.encoder_cpr = wire::get_u16(payload + 11);
    m.encoder_invert = payload[13];
    m.motor_invert = payload[14];
    m.wheel_diameter_um = wire::get_u32(payload + 15);
    m.steering_center_cdeg = wire::get_u16(payload + 19);
    m.steering_min_cdeg = wire::get_u16(payload + 21);
    m.steering_max_cdeg = wire::get_u16(payload + 23);
    m.steering_step_cdeg = wire::get_u16(payload + 25);
    m.servo_min_us = wire::get_u16(payload + 27);
    m.servo_max_us = wire::get_u16(payload + 29);
    m.esc_min_us = wire::get_u16(payload + 31);
    m.esc_neutral_us = wire::get_u16(payload + 33);
    m.esc_max_us = wire::get_u16(payload + 35);
    m.esc_arm_ms = wire::get_u16(payload + 37);
    m.feedback_hz = payload[39];
    return true;
}

uint8_t check_ranges(const SetConfig& m) {
    if (m.watchdog_ms < 50 || m.watchdog_ms > 2000) return 0;
    if (m.accel_limit_mm_s2 < 1) return 2;
    if (m.decel_limit_mm_s2 < 1) return 3;
    if (m.max_wheel_speed_mm_s < 1 || m.max_wheel_speed_mm_s > 20000) return 4;
    if (m.max_effort_permille > 1000) return 5;
    if (m.encoder_cpr < 1) return 6;
    if (m.encoder_invert > 3) return 7;
    if (m.motor_invert > 3) return 8;
    if (m.wheel_diameter_um < 1000UL || m.wheel_diameter_um > 1000000UL) return 9;
    if (m.steering_center_cdeg > 18000) return 10;
    if (m.steering_min_cdeg > 18000) return 11;
    if (m.steering_max_cdeg > 18000) return 12;
    if (m.steering_step_cdeg > 9000) return 13;
    if (m.servo_min_us < 400 || m.servo_min_us > 2600) return 14;
    if (m.servo_max_us < 400 || m.servo_max_us > 2600) return 15;
    if (m.esc_min_us < 800 || m.esc_min_us > 2200) return 16;
    if (m.esc_neutral_us < 800 || m.esc_neutral_us > 2200) return 17;
    if (m.esc_max_us < 800 || m.esc_max_us > 2200) return 18;
    if (m.esc_arm_ms > 10000) return 19;
    if (m.feedback_hz < 1 || m.feedback_hz > 100) return 20;
    return ALL_FIELDS_VALID;
}

uint8_t pack(const GetConfig& /*m*/, uint8_t* payload) {
    (void)payload;
    return 0;
}

bool unpack(const uint8_t* /*payload*/, uint8_t len, GetConfig& /*m*/) {
    if (len != 0) return false;
    return true;
}

uint8_t check_ranges(const GetConfig& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const SaveConfig& /*m*/, uint8_t* payload) {
    (void)payload;
    return 0;
}

bool unpack(const uint8_t* /*payload*/, uint8_t len, SaveConfig& /*m*/) {
    if (len != 0) return false;
    return true;
}

uint8_t check_ranges(const SaveConfig& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const ResetOdometry& /*m*/, uint8_t* payload) {
    (void)payload;
    return 0;
}

bool unpack(const uint8_t* /*payload*/, uint8_t len, ResetOdometry& /*m*/) {
    if (len != 0) return false;
    return true;
}

uint8_t check_ranges(const ResetOdometry& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const GetLinkStats& /*m*/, uint8_t* payload) {
    (void)payload;
    return 0;
}

bool unpack(const uint8_t* /*payload*/, uint8_t len, GetLinkStats& /*m*/) {
    if (len != 0) return false;
    return true;
}

uint8_t check_ranges(const GetLinkStats& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const SetWheelSpeeds& m, uint8_t* payload) {
    wire::put_i16(payload + 0, m.left_mm_s);
    wire::put_i16(payload + 2, m.right_mm_s);
    return 4;
}

bool unpack(const uint8_t* payload, uint8_t len, SetWheelSpeeds& m) {
    if (len != 4) return false;
    m.left_mm_s = wire::get_i16(payload + 0);
    m.right_mm_s = wire::get_i16(payload + 2);
    return true;
}

uint8_t check_ranges(const SetWheelSpeeds& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const SetAckermann& m, uint8_t* payload) {
    wire::put_i16(payload + 0, m.speed_mm_s);
    wire::put_i16(payload + 2, m.steering_mrad);
    return 4;
}

bool unpack(const uint8_t* payload, uint8_t len, SetAckermann& m) {
    if (len != 4) return false;
    m.speed_mm_s = wire::get_i16(payload + 0);
    m.steering_mrad = wire::get_i16(payload + 2);
    return true;
}

uint8_t check_ranges(const SetAckermann& m) {
    if (m.steering_mrad < -1571 || m.steering_mrad > 1571) return 1;
    return ALL_FIELDS_VALID;
}

uint8_t pack(const Identity& m, uint8_t* payload) {
    payload[0] = m.protocol_version;
    wire::put_u32(payload + 1, m.spec_hash);
    for (uint8_t i = 0; i < 3; ++i) {
        payload[5 + i * 1] = m.firmware_version[i];
    }
    payload[8] = static_cast<uint8_t>(m.board);
    wire::put_u16(payload + 9, m.capabilities);
    wire::put_u32(payload + 11, m.boot_id);
    wire::put_u32(payload + 15, m.uptime_ms);
    payload[19] = static_cast<uint8_t>(m.reason);
    payload[20] = m.hello_seq;
    wire::put_u16(payload + 21, m.watchdog_ms);
    payload[23] = static_cast<uint8_t>(m.feedback_mode);
    payload[24] = m.feedback_hz;
    const uint8_t n = m.robot_name_len < 24 ? m.robot_name_len : 24;
    for (uint8_t i = 0; i < n; ++i) payload[25 + i] = static_cast<uint8_t>(m.robot_name[i]);
    return static_cast<uint8_t>(25 + n);
}

bool unpack(const uint8_t* payload, uint8_t len, Identity& m) {
    if (len < 25 || len > 49) return false;
    m.protocol_version = payload[0];
    m.spec_hash = wire::get_u32(payload + 1);
    for (uint8_t i = 0; i < 3; ++i) {
        m.firmware_version[i] = payload[5 + i * 1];
    }
    if (!is_valid_Board(payload[8])) return false;
    m.board = static_cast<Board>(payload[8]);
    m.capabilities = wire::get_u16(payload + 9);
    if (m.capabilities & static_cast<uint16_t>(~Capability::MASK)) return false;
    m.boot_id = wire::get_u32(payload + 11);
    m.uptime_ms = wire::get_u32(payload + 15);
    if (!is_valid_IdentityReason(payload[19])) return false;
    m.reason = static_cast<IdentityReason>(payload[19]);
    m.hello_seq = payload[20];
    m.watchdog_ms = wire::get_u16(payload + 21);
    if (!is_valid_FeedbackMode(payload[23])) return false;
    m.feedback_mode = static_cast<FeedbackMode>(payload[23]);
    m.feedback_hz = payload[24];
    m.robot_name_len = static_cast<uint8_t>(len - 25);
    for (uint8_t i = 0; i < m.robot_name_len; ++i) {
        if (payload[25 + i] > 0x7F) return false;  // ASCII only
        m.robot_name[i] = static_cast<char>(payload[25 + i]);
    }
    return true;
}

uint8_t check_ranges(const Identity& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const Pong& m, uint8_t* payload) {
    wire::put_u32(payload + 0, m.host_time_us);
    wire::put_u32(payload + 4, m.mcu_time_us);
    return 8;
}

bool unpack(const uint8_t* payload, uint8_t len, Pong& m) {
    if (len != 8) return false;
    m.host_time_us = wire::get_u32(payload + 0);
    m.mcu_time_us = wire::get_u32(payload + 4);
    return true;
}

uint8_t check_ranges(const Pong& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const Ack& m, uint8_t* payload) {
    payload[0] = m.req_id;
    payload[1] = m.req_seq;
    return 2;
}

bool unpack(const uint8_t* payload, uint8_t len, Ack& m) {
    if (len != 2) return false;
    m.req_id = payload[0];
    m.req_seq = payload[1];
    return true;
}

uint8_t check_ranges(const Ack& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const Nack& m, uint8_t* payload) {
    payload[0] = m.req_id;
    payload[1] = m.req_seq;
    payload[2] = static_cast<uint8_t>(m.reason);
    payload[3] = m.detail;
    return 4;
}

bool unpack(const uint8_t* payload, uint8_t len, Nack& m) {
    if (len != 4) return false;
    m.req_id = payload[0];
    m.req_seq = payload[1];
    if (!is_valid_NackReason(payload[2])) return false;
    m.reason = static_cast<NackReason>(payload[2]);
    m.detail = payload[3];
    return true;
}

uint8_t check_ranges(const Nack& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const Pid& m, uint8_t* payload) {
    payload[0] = m.req_seq;
    payload[1] = m.wheel;
    wire::put_f32(payload + 2, m.kp);
    wire::put_f32(payload + 6, m.ki);
    wire::put_f32(payload + 10, m.kd);
    wire::put_f32(payload + 14, m.kf);
    return 18;
}

bool unpack(const uint8_t* payload, uint8_t len, Pid& m) {
    if (len != 18) return false;
    m.req_seq = payload[0];
    m.wheel = payload[1];
    m.kp = wire::get_f32(payload + 2);
    m.ki = wire::get_f32(payload + 6);
    m.kd = wire::get_f32(payload + 10);
    m.kf = wire::get_f32(payload + 14);
    return true;
}

uint8_t check_ranges(const Pid& m) {
    if (!(m.kp >= 0.0f && m.kp <= 1000.0f)) return 2;
    if (!(m.ki >= 0.0f && m.ki <= 1000.0f)) return 3;
    if (!(m.kd >= 0.0f && m.kd <= 1000.0f)) return 4;
    if (!(m.kf >= 0.0f && m.kf <= 1000.0f)) return 5;
    return ALL_FIELDS_VALID;
}

uint8_t pack(const Config& m, uint8_t* payload) {
    payload[0] = m.req_seq;
    wire::put_u16(payload + 1, m.watchdog_ms);
    payload[3] = static_cast<uint8_t>(m.safe_state);
    wire::put_u16(payload + 4, m.accel_limit_mm_s2);
    wire::put_u16(payload + 6, m.decel_limit_mm_s2);
    wire::put_u16(payload + 8, m.max_wheel_speed_mm_s);
    wire::put_u16(payload + 10, m.max_effort_permille);
    wire::put_u16(payload + 12, m.encoder_cpr);
    payload[14] = m.encoder_invert;
    payload[15] = m.motor_invert;
    wire::put_u32(payload + 16, m.wheel_diameter_um);
    wire::put_u16(payload + 20, m.steering_center_cdeg);
    wire::put_u16(payload + 22, m.steering_min_cdeg);
    wire::put_u16(payload + 24, m.steering_max_cdeg);
    wire::put_u16(payload + 26, m.steering_step_cdeg);
    wire::put_u16(payload + 28, m.servo_min_us);
    wire::put_u16(payload + 30, m.servo_max_us);
    wire::put_u16(payload + 32, m.esc_min_us);
    wire::put_u16(payload + 34, m.esc_neutral_us);
    wire::put_u16(payload + 36, m.esc_max_us);
    wire::put_u16(payload + 38, m.esc_arm_ms);
    payload[40] = m.feedback_hz;
    return 41;
}

bool unpack(const uint8_t* payload, uint8_t len, Config& m) {
    if (len != 41) return false;
    m.req_seq = payload[0];
    m.watchdog_ms = wire::get_u16(payload + 1);
    if (!is_valid_SafeState(payload[3])) return false;
    m.safe_state = static_cast<SafeState>(payload[3]);
    m.accel_limit_mm_s2 = wire::get_u16(payload + 4);
    m.decel_limit_mm_s2 = wire::get_u16(payload + 6);
    m.max_wheel_speed_mm_s = wire::get_u16(payload + 8);
    m.max_effort_permille = wire::get_u16(payload + 10);
    m.encoder_cpr = wire::get_u16(payload + 12);
    m.encoder_invert = payload[14];
    m.motor_invert = payload[15];
    m.wheel_diameter_um = wire::get_u32(payload + 16);
    m.steering_center_cdeg = wire::get_u16(payload + 20);
    m.steering_min_cdeg = wire::get_u16(payload + 22);
    m.steering_max_cdeg = wire::get_u16(payload + 24);
    m.steering_step_cdeg = wire::get_u16(payload + 26);
    m.servo_min_us = wire::get_u16(payload + 28);
    m.servo_max_us = wire::get_u16(payload + 30);
    m.esc_min_us = wire::get_u16(payload + 32);
    m.esc_neutral_us = wire::get_u16(payload + 34);
    m.esc_max_us = wire::get_u16(payload + 36);
    m.esc_arm_ms = wire::get_u16(payload + 38);
    m.feedback_hz = payload[40];
    return true;
}

uint8_t check_ranges(const Config& m) {
    if (m.watchdog_ms < 50 || m.watchdog_ms > 2000) return 1;
    if (m.accel_limit_mm_s2 < 1) return 3;
    if (m.decel_limit_mm_s2 < 1) return 4;
    if (m.max_wheel_speed_mm_s < 1 || m.max_wheel_speed_mm_s > 20000) return 5;
    if (m.max_effort_permille > 1000) return 6;
    if (m.encoder_cpr < 1) return 7;
    if (m.encoder_invert > 3) return 8;
    if (m.motor_invert > 3) return 9;
    if (m.wheel_diameter_um < 1000UL || m.wheel_diameter_um > 1000000UL) return 10;
    if (m.steering_center_cdeg > 18000) return 11;
    if (m.steering_min_cdeg > 18000) return 12;
    if (m.steering_max_cdeg > 18000) return 13;
    if (m.steering_step_cdeg > 9000) return 14;
    if (m.servo_min_us < 400 || m.servo_min_us > 2600) return 15;
    if (m.servo_max_us < 400 || m.servo_max_us > 2600) return 16;
    if (m.esc_min_us < 800 || m.esc_min_us > 2200) return 17;
    if (m.esc_neutral_us < 800 || m.esc_neutral_us > 2200) return 18;
    if (m.esc_max_us < 800 || m.esc_max_us > 2200) return 19;
    if (m.esc_arm_ms > 10000) return 20;
    if (m.feedback_hz < 1 || m.feedback_hz > 100) return 21;
    return ALL_FIELDS_VALID;
}

uint8_t pack(const LinkStats& m, uint8_t* payload) {
    payload[0] = m.req_seq;
    wire::put_u32(payload + 1, m.frames_ok);
    wire::put_u32(payload + 5, m.crc_errors);
    wire::put_u32(payload + 9, m.cobs_errors);
    wire::put_u32(payload + 13, m.length_errors);
    wire::put_u32(payload + 17, m.unknown_ids);
    wire::put_u32(payload + 21, m.value_errors);
    wire::put_u32(payload + 25, m.seq_gaps);
    wire::put_u32(payload + 29, m.bytes_discarded);
    wire::put_u32(payload + 33, m.rx_overruns);
    wire::put_u32(payload + 37, m.duplicates);
    wire::put_u32(payload + 41, m.frames_sent);
    return 45;
}

bool unpack(const uint8_t* payload, uint8_t len, LinkStats& m) {
    if (len != 45) return false;
    m.req_seq = payload[0];
    m.frames_ok = wire::get_u32(payload + 1);
    m.crc_errors = wire::get_u32(payload + 5);
    m.cobs_errors = wire::get_u32(payload + 9);
    m.length_errors = wire::get_u32(payload + 13);
    m.unknown_ids = wire::get_u32(payload + 17);
    m.value_errors = wire::get_u32(payload + 21);
    m.seq_gaps = wire::get_u32(payload + 25);
    m.bytes_discarded = wire::get_u32(payload + 29);
    m.rx_overruns = wire::get_u32(payload + 33);
    m.duplicates = wire::get_u32(payload + 37);
    m.frames_sent = wire::get_u32(payload + 41);
    return true;
}

uint8_t check_ranges(const LinkStats& /*m*/) {
    return ALL_FIELDS_VALID;
}

uint8_t pack(const Feedback& m, uint8_t* payload) {
    wire::put_u32(payload + 0, m.boot_id);
    wire::put_u32(payload + 4, m.mcu_time_us);
    wire::put_u16(payload + 8, m.tick);
    payload[10] = m.ack_seq;
    wire::put_u16(payload + 11, m.ack_tick);
    payload[13] = m.status;
    payload[14] = static_cast<uint8_t>(m.failsafe_reason);
    for (uint8_t i = 0; i < 2; ++i) {
        wire::put_i32(payload + 15 + i * 4, m.encoder_counts[i]);
    }
    for (uint8_t i = 0; i < 2; ++i) {
        wire::put_i16(payload + 23 + i * 2, m.wheel_speed_mm_s[i]);
    }
    for (uint8_t i = 0; i < 2; ++i) {
        wire::put_i16(payload + 27 + i * 2, m.effort_permille[i]);
    }
    wire::put_i16(payload + 31, m.steering_mrad);
    return 33;
}

bool unpack(const uint8_t* payload, uint8_t len, Feedback& m) {
    if (len != 33) return false;
    m.boot_id = wire::get_u32(payload + 0);
    m.mcu_time_us = wire::get_u32(payload + 4);
    m.tick = wire::get_u16(payload + 8);
    m.ack_seq = payload[10];
    m.ack_tick = wire::get_u16(payload + 11);
    m.status = payload[13];
    if (m.status & static_cast<uint8_t>(~Status::MASK)) return false;
    if (!is_valid_FailsafeReason(payload[14])) return false;
    m.failsafe_reason = static_cast<FailsafeReason>(payload[14]);
    for (uint8_t i = 0; i < 2; ++i) {
        m.encoder_counts[i] = wire::get_i32(payload + 15 + i * 4);
    }
    for (uint8_t i = 0; i < 2; ++i) {
        m.wheel_speed_mm_s[i] = wire::get_i16(payload + 23 + i * 2);
    }
    for (uint8_t i = 0; i < 2; ++i) {
        m.effort_permille[i] = wire::get_i16(payload + 27 + i * 2);
    }
    m.steering_mrad = wire::get_i16(payload + 31);
    return true;
}

uint8_t check_ranges(const Feedback& m) {
    for (uint8_t k = 0; k < 2; ++k) {
        if (m.effort_permille[k] < -1000 || m.effort_permille[k] > 1000) return 9;
    }
    if (m.steering_mrad < -1571 || m.steering_mrad > 1571) return 10;
    return ALL_FIELDS_VALID;
}

uint8_t pack(const Log& m, uint8_t* payload) {
    payload[0] = static_cast<uint8_t>(m.level);
    const uint8_t n = m.text_len < 60 ? m.text_len : 60;
    for (uint8_t i = 0; i < n; ++i) payload[1 + i] = static_cast<uint8_t>(m.text[i]);
    return static_cast<uint8_t>(1 + n);
}

bool unpack(const uint8_t* payload, uint8_t len, Log& m) {
    if (len < 1 || len > 61) return false;
    if (!is_valid_LogLevel(payload[0])) return false;
    m.level = static_cast<LogLevel>(payload[0]);
    m.text_len = static_cast<uint8_t>(len - 1);
    for (uint8_t i = 0; i < m.text_len; ++i) {
        if (payload[1 + i] > 0x7F) return false;  // ASCII only
        m.text[i] = static_cast<char>(payload[1 + i]);
    }
    return true;
}

uint8_t check_ranges(const Log& /*m*/) {
    return ALL_FIELDS_VALID;
}

const uint8_t TRANSITIONS[TRANSITION_COUNT][6] ROVERLINK_PROGMEM = {
    {0, 0, GUARD_NONE, 1, 0x09, 0x00},  // BOOT INIT_DONE -> IDLE
    {1, 1, 1, 2, 0x02, 0x00},  // IDLE HELLO [compatible] -> DISARMED
    {1, 1, 1 | GUARD_NEGATED, 1, 0x04, 0x00},  // IDLE HELLO [!compatible] -> IDLE
    {2, 1, 1, 2, 0x8A, 0x00},  // DISARMED HELLO [compatible] -> DISARMED
    {3, 1, 1, 2, 0x8A, 0x00},  // ARMED HELLO [compatible] -> DISARMED
    {4, 1, 1, 2, 0x8A, 0x00},  // FAILSAFE HELLO [compatible] -> DISARMED
    {2, 1, 1 | GUARD_NEGATED, 1, 0x8C, 0x00},  // DISARMED HELLO [!compatible] -> IDLE
    {3, 1, 1 | GUARD_NEGATED, 1, 0x8C, 0x00},  // ARMED HELLO [!compatible] -> IDLE
    {4, 1, 1 | GUARD_NEGATED, 1, 0x8C, 0x00},  // FAILSAFE HELLO [!compatible] -> IDLE
    {1, 2, GUARD_NONE, 1, 0x00, 0x02},  // IDLE ARM -> IDLE
    {2, 2, 2, 3, 0xB0, 0x01},  // DISARMED ARM [boot_id_matches] -> ARMED
    {4, 2, 2, 3, 0xB0, 0x01},  // FAILSAFE ARM [boot_id_matches] -> ARMED
    {3, 2, 2, 3, 0x20, 0x01},  // ARMED ARM [boot_id_matches] -> ARMED
    {2, 2, 2 | GUARD_NEGATED, 2, 0x00, 0x02},  // DISARMED ARM [!boot_id_matches] -> DISARMED
    {3, 2, 2 | GUARD_NEGATED, 3, 0x00, 0x02},  // ARMED ARM [!boot_id_matches] -> ARMED
    {4, 2, 2 | GUARD_NEGATED, 4, 0x00, 0x02},  // FAILSAFE ARM [!boot_id_matches] -> FAILSAFE
    {1, 3, GUARD_NONE, 1, 0x00, 0x01},  // IDLE DISARM -> IDLE
    {2, 3, GUARD_NONE, 2, 0x88, 0x01},  // DISARMED DISARM -> DISARMED
    {3, 3, GUARD_NONE, 2, 0x88, 0x01},  // ARMED DISARM -> DISARMED
    {4, 3, GUARD_NONE, 2, 0x88, 0x01},  // FAILSAFE DISARM -> DISARMED
    {3, 4, GUARD_NONE, 3, 0x00, 0x04},  // ARMED SETPOINT -> ARMED
    {1, 4, GUARD_NONE, 1, 0x00, 0x02},  // IDLE SETPOINT -> IDLE
    {2, 4, GUARD_NONE, 2, 0x00, 0x02},  // DISARMED SETPOINT -> DISARMED
    {4, 4, GUARD_NONE, 4, 0x00, 0x02},  // FAILSAFE SETPOINT -> FAILSAFE
    {2, 5, GUARD_NONE, 2, 0x20, 0x00},  // DISARMED VALID_FRAME -> DISARMED
    {3, 5, GUARD_NONE, 3, 0x20, 0x00},  // ARMED VALID_FRAME -> ARMED
    {4, 5, GUARD_NONE, 4, 0x20, 0x00},  // FAILSAFE VALID_FRAME -> FAILSAFE
    {3, 6, GUARD_NONE, 4, 0x48, 0x00},  // ARMED WATCHDOG_EXPIRED -> FAILSAFE
    {3, 7, GUARD_NONE, 4, 0x48, 0x00},  // ARMED FAULT -> FAILSAFE
    {2, 7, GUARD_NONE, 4, 0x48, 0x00},  // DISARMED FAULT -> FAILSAFE
    {0, 8, GUARD_NONE, 0, 0x08, 0x00},  // BOOT RESET -> BOOT
    {1, 8, GUARD_NONE, 0, 0x08, 0x00},  // IDLE RESET -> BOOT
    {2, 8, GUARD_NONE, 0, 0x08, 0x00},  // DISARMED RESET -> BOOT
    {3, 8, GUARD_NONE, 0, 0x08, 0x00},  // ARMED RESET -> BOOT
    {4, 8, GUARD_NONE, 0, 0x08, 0x00},  // FAILSAFE RESET -> BOOT
};

}  // namespace proto
}  // namespace roverlink
