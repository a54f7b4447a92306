// DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
// spec hash: 0xBDF31659
#include "roverlink_protocol.h"

namespace roverlink {
namespace proto {

// Every struct is its payload's image: each member at its wire offset with its wire width (no
// int, no double, no padding), then the variable-length field's <name>_len.
static_assert(Hello::PAYLOAD_MAX <= MAX_PAYLOAD, "HELLO payload exceeds MAX_PAYLOAD");
static_assert(offsetof(Hello, protocol_version) == 0, "HELLO.protocol_version is not at its wire offset");
static_assert(offsetof(Hello, spec_hash) == 1, "HELLO.spec_hash is not at its wire offset");
static_assert(offsetof(Hello, watchdog_ms) == 5, "HELLO.watchdog_ms is not at its wire offset");
static_assert(offsetof(Hello, feedback_mode) == 7, "HELLO.feedback_mode is not at its wire offset");
static_assert(offsetof(Hello, feedback_hz) == 8, "HELLO.feedback_hz is not at its wire offset");
static_assert(sizeof(Hello) == Hello::PAYLOAD_MAX, "HELLO is not its payload's image");
static_assert(Ping::PAYLOAD_MAX <= MAX_PAYLOAD, "PING payload exceeds MAX_PAYLOAD");
static_assert(offsetof(Ping, host_time_us) == 0, "PING.host_time_us is not at its wire offset");
static_assert(sizeof(Ping) == Ping::PAYLOAD_MAX, "PING is not its payload's image");
static_assert(Arm::PAYLOAD_MAX <= MAX_PAYLOAD, "ARM payload exceeds MAX_PAYLOAD");
static_assert(offsetof(Arm, boot_id) == 0, "ARM.boot_id is not at its wire offset");
static_assert(sizeof(Arm) == Arm::PAYLOAD_MAX, "ARM is not its payload's image");
static_assert(Disarm::PAYLOAD_MAX <= MAX_PAYLOAD, "DISARM payload exceeds MAX_PAYLOAD");
static_assert(SetPid::PAYLOAD_MAX <= MAX_PAYLOAD, "SET_PID payload exceeds MAX_PAYLOAD");
static_assert(offsetof(SetPid, wheel) == 0, "SET_PID.wheel is not at its wire offset");
static_assert(offsetof(SetPid, kp) == 1, "SET_PID.kp is not at its wire offset");
static_assert(offsetof(SetPid, ki) == 5, "SET_PID.ki is not at its wire offset");
static_assert(offsetof(SetPid, kd) == 9, "SET_PID.kd is not at its wire offset");
static_assert(offsetof(SetPid, kf) == 13, "SET_PID.kf is not at its wire offset");
static_assert(offsetof(SetPid, ks) == 17, "SET_PID.ks is not at its wire offset");
static_assert(sizeof(SetPid) == SetPid::PAYLOAD_MAX, "SET_PID is not its payload's image");
static_assert(GetPid::PAYLOAD_MAX <= MAX_PAYLOAD, "GET_PID payload exceeds MAX_PAYLOAD");
static_assert(offsetof(GetPid, wheel) == 0, "GET_PID.wheel is not at its wire offset");
static_assert(sizeof(GetPid) == GetPid::PAYLOAD_MAX, "GET_PID is not its payload's image");
static_assert(SetConfig::PAYLOAD_MAX <= MAX_PAYLOAD, "SET_CONFIG payload exceeds MAX_PAYLOAD");
static_assert(offsetof(SetConfig, watchdog_ms) == 0, "SET_CONFIG.watchdog_ms is not at its wire offset");
static_assert(offsetof(SetConfig, safe_state) == 2, "SET_CONFIG.safe_state is not at its wire offset");
static_assert(offsetof(SetConfig, accel_limit_mm_s2) == 3, "SET_CONFIG.accel_limit_mm_s2 is not at its wire offset");
static_assert(offsetof(SetConfig, decel_limit_mm_s2) == 5, "SET_CONFIG.decel_limit_mm_s2 is not at its wire offset");
static_assert(offsetof(SetConfig, max_wheel_speed_mm_s) == 7, "SET_CONFIG.max_wheel_speed_mm_s is not at its wire offset");
static_assert(offsetof(SetConfig, max_effort_permille) == 9, "SET_CONFIG.max_effort_permille is not at its wire offset");
static_assert(offsetof(SetConfig, encoder_cpr) == 11, "SET_CONFIG.encoder_cpr is not at its wire offset");
static_assert(offsetof(SetConfig, encoder_invert) == 13, "SET_CONFIG.encoder_invert is not at its wire offset");
static_assert(offsetof(SetConfig, motor_invert) == 14, "SET_CONFIG.motor_invert is not at its wire offset");
static_assert(offsetof(SetConfig, wheel_diameter_um) == 15, "SET_CONFIG.wheel_diameter_um is not at its wire offset");
static_assert(offsetof(SetConfig, steering_center_cdeg) == 19, "SET_CONFIG.steering_center_cdeg is not at its wire offset");
static_assert(offsetof(SetConfig, steering_min_cdeg) == 21, "SET_CONFIG.steering_min_cdeg is not at its wire offset");
static_assert(offsetof(SetConfig, steering_max_cdeg) == 23, "SET_CONFIG.steering_max_cdeg is not at its wire offset");
static_assert(offsetof(SetConfig, steering_step_cdeg) == 25, "SET_CONFIG.steering_step_cdeg is not at its wire offset");
static_assert(offsetof(SetConfig, servo_min_us) == 27, "SET_CONFIG.servo_min_us is not at its wire offset");
static_assert(offsetof(SetConfig, servo_max_us) == 29, "SET_CONFIG.servo_max_us is not at its wire offset");
static_assert(offsetof(SetConfig, esc_min_us) == 31, "SET_CONFIG.esc_min_us is not at its wire offset");
static_assert(offsetof(SetConfig, esc_neutral_us) == 33, "SET_CONFIG.esc_neutral_us is not at its wire offset");
static_assert(offsetof(SetConfig, esc_max_us) == 35, "SET_CONFIG.esc_max_us is not at its wire offset");
static_assert(offsetof(SetConfig, esc_arm_ms) == 37, "SET_CONFIG.esc_arm_ms is not at its wire offset");
static_assert(offsetof(SetConfig, feedback_hz) == 39, "SET_CONFIG.feedback_hz is not at its wire offset");
static_assert(sizeof(SetConfig) == SetConfig::PAYLOAD_MAX, "SET_CONFIG is not its payload's image");
static_assert(GetConfig::PAYLOAD_MAX <= MAX_PAYLOAD, "GET_CONFIG payload exceeds MAX_PAYLOAD");
static_assert(SaveConfig::PAYLOAD_MAX <= MAX_PAYLOAD, "SAVE_CONFIG payload exceeds MAX_PAYLOAD");
static_assert(ResetOdometry::PAYLOAD_MAX <= MAX_PAYLOAD, "RESET_ODOMETRY payload exceeds MAX_PAYLOAD");
static_assert(GetLinkStats::PAYLOAD_MAX <= MAX_PAYLOAD, "GET_LINK_STATS payload exceeds MAX_PAYLOAD");
static_assert(SetLights::PAYLOAD_MAX <= MAX_PAYLOAD, "SET_LIGHTS payload exceeds MAX_PAYLOAD");
static_assert(offsetof(SetLights, mode) == 0, "SET_LIGHTS.mode is not at its wire offset");
static_assert(offsetof(SetLights, steady) == 1, "SET_LIGHTS.steady is not at its wire offset");
static_assert(offsetof(SetLights, slow) == 2, "SET_LIGHTS.slow is not at its wire offset");
static_assert(offsetof(SetLights, fast) == 3, "SET_LIGHTS.fast is not at its wire offset");
static_assert(sizeof(SetLights) == SetLights::PAYLOAD_MAX, "SET_LIGHTS is not its payload's image");
static_assert(GetLights::PAYLOAD_MAX <= MAX_PAYLOAD, "GET_LIGHTS payload exceeds MAX_PAYLOAD");
static_assert(SetWheelSpeeds::PAYLOAD_MAX <= MAX_PAYLOAD, "SET_WHEEL_SPEEDS payload exceeds MAX_PAYLOAD");
static_assert(offsetof(SetWheelSpeeds, left_mm_s) == 0, "SET_WHEEL_SPEEDS.left_mm_s is not at its wire offset");
static_assert(offsetof(SetWheelSpeeds, right_mm_s) == 2, "SET_WHEEL_SPEEDS.right_mm_s is not at its wire offset");
static_assert(sizeof(SetWheelSpeeds) == SetWheelSpeeds::PAYLOAD_MAX, "SET_WHEEL_SPEEDS is not its payload's image");
static_assert(SetAckermann::PAYLOAD_MAX <= MAX_PAYLOAD, "SET_ACKERMANN payload exceeds MAX_PAYLOAD");
static_assert(offsetof(SetAckermann, speed_mm_s) == 0, "SET_ACKERMANN.speed_mm_s is not at its wire offset");
static_assert(offsetof(SetAckermann, steering_mrad) == 2, "SET_ACKERMANN.steering_mrad is not at its wire offset");
static_assert(sizeof(SetAckermann) == SetAckermann::PAYLOAD_MAX, "SET_ACKERMANN is not its payload's image");
static_assert(Identity::PAYLOAD_MAX <= MAX_PAYLOAD, "IDENTITY payload exceeds MAX_PAYLOAD");
static_assert(offsetof(Identity, protocol_version) == 0, "IDENTITY.protocol_version is not at its wire offset");
static_assert(offsetof(Identity, spec_hash) == 1, "IDENTITY.spec_hash is not at its wire offset");
static_assert(offsetof(Identity, firmware_version) == 5, "IDENTITY.firmware_version is not at its wire offset");
static_assert(offsetof(Identity, board) == 8, "IDENTITY.board is not at its wire offset");
static_assert(offsetof(Identity, capabilities) == 9, "IDENTITY.capabilities is not at its wire offset");
static_assert(offsetof(Identity, boot_id) == 11, "IDENTITY.boot_id is not at its wire offset");
static_assert(offsetof(Identity, uptime_ms) == 15, "IDENTITY.uptime_ms is not at its wire offset");
static_assert(offsetof(Identity, reason) == 19, "IDENTITY.reason is not at its wire offset");
static_assert(offsetof(Identity, hello_seq) == 20, "IDENTITY.hello_seq is not at its wire offset");
static_assert(offsetof(Identity, watchdog_ms) == 21, "IDENTITY.watchdog_ms is not at its wire offset");
static_assert(offsetof(Identity, feedback_mode) == 23, "IDENTITY.feedback_mode is not at its wire offset");
static_assert(offsetof(Identity, feedback_hz) == 24, "IDENTITY.feedback_hz is not at its wire offset");
static_assert(offsetof(Identity, robot_name) == 25, "IDENTITY.robot_name is not at its wire offset");
static_assert(offsetof(Identity, robot_name_len) == Identity::PAYLOAD_MAX, "IDENTITY.robot_name_len must follow the payload image");
static_assert(sizeof(Identity) == Identity::PAYLOAD_MAX + 1, "IDENTITY is not its payload's image");
static_assert(Pong::PAYLOAD_MAX <= MAX_PAYLOAD, "PONG payload exceeds MAX_PAYLOAD");
static_assert(offsetof(Pong, host_time_us) == 0, "PONG.host_time_us is not at its wire offset");
static_assert(offsetof(Pong, mcu_time_us) == 4, "PONG.mcu_time_us is not at its wire offset");
static_assert(sizeof(Pong) == Pong::PAYLOAD_MAX, "PONG is not its payload's image");
static_assert(Ack::PAYLOAD_MAX <= MAX_PAYLOAD, "ACK payload exceeds MAX_PAYLOAD");
static_assert(offsetof(Ack, req_id) == 0, "ACK.req_id is not at its wire offset");
static_assert(offsetof(Ack, req_seq) == 1, "ACK.req_seq is not at its wire offset");
static_assert(sizeof(Ack) == Ack::PAYLOAD_MAX, "ACK is not its payload's image");
static_assert(Nack::PAYLOAD_MAX <= MAX_PAYLOAD, "NACK payload exceeds MAX_PAYLOAD");
static_assert(offsetof(Nack, req_id) == 0, "NACK.req_id is not at its wire offset");
static_assert(offsetof(Nack, req_seq) == 1, "NACK.req_seq is not at its wire offset");
static_assert(offsetof(Nack, reason) == 2, "NACK.reason is not at its wire offset");
static_assert(offsetof(Nack, detail) == 3, "NACK.detail is not at its wire offset");
static_assert(sizeof(Nack) == Nack::PAYLOAD_MAX, "NACK is not its payload's image");
static_assert(Pid::PAYLOAD_MAX <= MAX_PAYLOAD, "PID payload exceeds MAX_PAYLOAD");
static_assert(offsetof(Pid, req_seq) == 0, "PID.req_seq is not at its wire offset");
static_assert(offsetof(Pid, wheel) == 1, "PID.wheel is not at its wire offset");
static_assert(offsetof(Pid, kp) == 2, "PID.kp is not at its wire offset");
static_assert(offsetof(Pid, ki) == 6, "PID.ki is not at its wire offset");
static_assert(offsetof(Pid, kd) == 10, "PID.kd is not at its wire offset");
static_assert(offsetof(Pid, kf) == 14, "PID.kf is not at its wire offset");
static_assert(offsetof(Pid, ks) == 18, "PID.ks is not at its wire offset");
static_assert(sizeof(Pid) == Pid::PAYLOAD_MAX, "PID is not its payload's image");
static_assert(Config::PAYLOAD_MAX <= MAX_PAYLOAD, "CONFIG payload exceeds MAX_PAYLOAD");
static_assert(offsetof(Config, req_seq) == 0, "CONFIG.req_seq is not at its wire offset");
static_assert(offsetof(Config, watchdog_ms) == 1, "CONFIG.watchdog_ms is not at its wire offset");
static_assert(offsetof(Config, safe_state) == 3, "CONFIG.safe_state is not at its wire offset");
static_assert(offsetof(Config, accel_limit_mm_s2) == 4, "CONFIG.accel_limit_mm_s2 is not at its wire offset");
static_assert(offsetof(Config, decel_limit_mm_s2) == 6, "CONFIG.decel_limit_mm_s2 is not at its wire offset");
static_assert(offsetof(Config, max_wheel_speed_mm_s) == 8, "CONFIG.max_wheel_speed_mm_s is not at its wire offset");
static_assert(offsetof(Config, max_effort_permille) == 10, "CONFIG.max_effort_permille is not at its wire offset");
static_assert(offsetof(Config, encoder_cpr) == 12, "CONFIG.encoder_cpr is not at its wire offset");
static_assert(offsetof(Config, encoder_invert) == 14, "CONFIG.encoder_invert is not at its wire offset");
static_assert(offsetof(Config, motor_invert) == 15, "CONFIG.motor_invert is not at its wire offset");
static_assert(offsetof(Config, wheel_diameter_um) == 16, "CONFIG.wheel_diameter_um is not at its wire offset");
static_assert(offsetof(Config, steering_center_cdeg) == 20, "CONFIG.steering_center_cdeg is not at its wire offset");
static_assert(offsetof(Config, steering_min_cdeg) == 22, "CONFIG.steering_min_cdeg is not at its wire offset");
static_assert(offsetof(Config, steering_max_cdeg) == 24, "CONFIG.steering_max_cdeg is not at its wire offset");
static_assert(offsetof(Config, steering_step_cdeg) == 26, "CONFIG.steering_step_cdeg is not at its wire offset");
static_assert(offsetof(Config, servo_min_us) == 28, "CONFIG.servo_min_us is not at its wire offset");
static_assert(offsetof(Config, servo_max_us) == 30, "CONFIG.servo_max_us is not at its wire offset");
static_assert(offsetof(Config, esc_min_us) == 32, "CONFIG.esc_min_us is not at its wire offset");
static_assert(offsetof(Config, esc_neutral_us) == 34, "CONFIG.esc_neutral_us is not at its wire offset");
static_assert(offsetof(Config, esc_max_us) == 36, "CONFIG.esc_max_us is not at its wire offset");
static_assert(offsetof(Config, esc_arm_ms) == 38, "CONFIG.esc_arm_ms is not at its wire offset");
static_assert(offsetof(Config, feedback_hz) == 40, "CONFIG.feedback_hz is not at its wire offset");
static_assert(sizeof(Config) == Config::PAYLOAD_MAX, "CONFIG is not its payload's image");
static_assert(LinkStats::PAYLOAD_MAX <= MAX_PAYLOAD, "LINK_STATS payload exceeds MAX_PAYLOAD");
static_assert(offsetof(LinkStats, req_seq) == 0, "LINK_STATS.req_seq is not at its wire offset");
static_assert(offsetof(LinkStats, frames_ok) == 1, "LINK_STATS.frames_ok is not at its wire offset");
static_assert(offsetof(LinkStats, crc_errors) == 5, "LINK_STATS.crc_errors is not at its wire offset");
static_assert(offsetof(LinkStats, cobs_errors) == 9, "LINK_STATS.cobs_errors is not at its wire offset");
static_assert(offsetof(LinkStats, length_errors) == 13, "LINK_STATS.length_errors is not at its wire offset");
static_assert(offsetof(LinkStats, unknown_ids) == 17, "LINK_STATS.unknown_ids is not at its wire offset");
static_assert(offsetof(LinkStats, value_errors) == 21, "LINK_STATS.value_errors is not at its wire offset");
static_assert(offsetof(LinkStats, bytes_discarded) == 25, "LINK_STATS.bytes_discarded is not at its wire offset");
static_assert(offsetof(LinkStats, seq_gaps) == 29, "LINK_STATS.seq_gaps is not at its wire offset");
static_assert(offsetof(LinkStats, duplicates) == 33, "LINK_STATS.duplicates is not at its wire offset");
static_assert(offsetof(LinkStats, frames_sent) == 37, "LINK_STATS.frames_sent is not at its wire offset");
static_assert(offsetof(LinkStats, rx_overruns) == 41, "LINK_STATS.rx_overruns is not at its wire offset");
static_assert(sizeof(LinkStats) == LinkStats::PAYLOAD_MAX, "LINK_STATS is not its payload's image");
static_assert(offsetof(LinkStats, crc_errors) - offsetof(LinkStats, frames_ok) == offsetof(DecoderCounters, crc_errors), "LINK_STATS.crc_errors is not where DecoderCounters keeps it");
static_assert(offsetof(LinkStats, cobs_errors) - offsetof(LinkStats, frames_ok) == offsetof(DecoderCounters, cobs_errors), "LINK_STATS.cobs_errors is not where DecoderCounters keeps it");
static_assert(offsetof(LinkStats, length_errors) - offsetof(LinkStats, frames_ok) == offsetof(DecoderCounters, length_errors), "LINK_STATS.length_errors is not where DecoderCounters keeps it");
static_assert(offsetof(LinkStats, unknown_ids) - offsetof(LinkStats, frames_ok) == offsetof(DecoderCounters, unknown_ids), "LINK_STATS.unknown_ids is not where DecoderCounters keeps it");
static_assert(offsetof(LinkStats, value_errors) - offsetof(LinkStats, frames_ok) == offsetof(DecoderCounters, value_errors), "LINK_STATS.value_errors is not where DecoderCounters keeps it");
static_assert(offsetof(LinkStats, bytes_discarded) - offsetof(LinkStats, frames_ok) == offsetof(DecoderCounters, bytes_discarded), "LINK_STATS.bytes_discarded is not where DecoderCounters keeps it");
static_assert(offsetof(LinkStats, duplicates) - offsetof(LinkStats, seq_gaps) == offsetof(LinkCounters, duplicates), "LINK_STATS.duplicates is not where LinkCounters keeps it");
static_assert(offsetof(LinkStats, frames_sent) - offsetof(LinkStats, seq_gaps) == offsetof(LinkCounters, frames_sent), "LINK_STATS.frames_sent is not where LinkCounters keeps it");
static_assert(offsetof(LinkStats, rx_overruns) - offsetof(LinkStats, seq_gaps) == offsetof(LinkCounters, rx_overruns), "LINK_STATS.rx_overruns is not where LinkCounters keeps it");
static_assert(LightsState::PAYLOAD_MAX <= MAX_PAYLOAD, "LIGHTS_STATE payload exceeds MAX_PAYLOAD");
static_assert(offsetof(LightsState, req_seq) == 0, "LIGHTS_STATE.req_seq is not at its wire offset");
static_assert(offsetof(LightsState, mode) == 1, "LIGHTS_STATE.mode is not at its wire offset");
static_assert(offsetof(LightsState, steady) == 2, "LIGHTS_STATE.steady is not at its wire offset");
static_assert(offsetof(LightsState, slow) == 3, "LIGHTS_STATE.slow is not at its wire offset");
static_assert(offsetof(LightsState, fast) == 4, "LIGHTS_STATE.fast is not at its wire offset");
static_assert(offsetof(LightsState, lit) == 5, "LIGHTS_STATE.lit is not at its wire offset");
static_assert(sizeof(LightsState) == LightsState::PAYLOAD_MAX, "LIGHTS_STATE is not its payload's image");
static_assert(Feedback::PAYLOAD_MAX <= MAX_PAYLOAD, "FEEDBACK payload exceeds MAX_PAYLOAD");
static_assert(offsetof(Feedback, boot_id) == 0, "FEEDBACK.boot_id is not at its wire offset");
static_assert(offsetof(Feedback, mcu_time_us) == 4, "FEEDBACK.mcu_time_us is not at its wire offset");
static_assert(offsetof(Feedback, tick) == 8, "FEEDBACK.tick is not at its wire offset");
static_assert(offsetof(Feedback, ack_seq) == 10, "FEEDBACK.ack_seq is not at its wire offset");
static_assert(offsetof(Feedback, ack_tick) == 11, "FEEDBACK.ack_tick is not at its wire offset");
static_assert(offsetof(Feedback, status) == 13, "FEEDBACK.status is not at its wire offset");
static_assert(offsetof(Feedback, failsafe_reason) == 14, "FEEDBACK.failsafe_reason is not at its wire offset");
static_assert(offsetof(Feedback, encoder_counts) == 15, "FEEDBACK.encoder_counts is not at its wire offset");
static_assert(offsetof(Feedback, wheel_speed_mm_s) == 23, "FEEDBACK.wheel_speed_mm_s is not at its wire offset");
static_assert(offsetof(Feedback, effort_permille) == 27, "FEEDBACK.effort_permille is not at its wire offset");
static_assert(offsetof(Feedback, steering_mrad) == 31, "FEEDBACK.steering_mrad is not at its wire offset");
static_assert(sizeof(Feedback) == Feedback::PAYLOAD_MAX, "FEEDBACK is not its payload's image");
static_assert(Log::PAYLOAD_MAX <= MAX_PAYLOAD, "LOG payload exceeds MAX_PAYLOAD");
static_assert(offsetof(Log, level) == 0, "LOG.level is not at its wire offset");
static_assert(offsetof(Log, text) == 1, "LOG.text is not at its wire offset");
static_assert(offsetof(Log, text_len) == Log::PAYLOAD_MAX, "LOG.text_len must follow the payload image");
static_assert(sizeof(Log) == Log::PAYLOAD_MAX + 1, "LOG is not its payload's image");
static_assert(sizeof(DecoderCounters) == 28, "DecoderCounters must have no padding");
static_assert(sizeof(LinkCounters) == 16, "LinkCounters must have no padding");

// msg_id, CRC_EXTRA, PAYLOAD_SIZE, PAYLOAD_MAX of every message: host to mcu first.
static const uint8_t MESSAGE_COUNT = 25;
static const uint8_t HOST_TO_MCU_COUNT = 15;
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
    {SetLights::ID, SetLights::CRC_EXTRA, SetLights::PAYLOAD_SIZE, SetLights::PAYLOAD_MAX},
    {GetLights::ID, GetLights::CRC_EXTRA, GetLights::PAYLOAD_SIZE, GetLights::PAYLOAD_MAX},
    {SetWheelSpeeds::ID, SetWheelSpeeds::CRC_EXTRA, SetWheelSpeeds::PAYLOAD_SIZE, SetWheelSpeeds::PAYLOAD_MAX},
    {SetAckermann::ID, SetAckermann::CRC_EXTRA, SetAckermann::PAYLOAD_SIZE, SetAckermann::PAYLOAD_MAX},
    {Identity::ID, Identity::CRC_EXTRA, Identity::PAYLOAD_SIZE, Identity::PAYLOAD_MAX},
    {Pong::ID, Pong::CRC_EXTRA, Pong::PAYLOAD_SIZE, Pong::PAYLOAD_MAX},
    {Ack::ID, Ack::CRC_EXTRA, Ack::PAYLOAD_SIZE, Ack::PAYLOAD_MAX},
    {Nack::ID, Nack::CRC_EXTRA, Nack::PAYLOAD_SIZE, Nack::PAYLOAD_MAX},
    {Pid::ID, Pid::CRC_EXTRA, Pid::PAYLOAD_SIZE, Pid::PAYLOAD_MAX},
    {Config::ID, Config::CRC_EXTRA, Config::PAYLOAD_SIZE, Config::PAYLOAD_MAX},
    {LinkStats::ID, LinkStats::CRC_EXTRA, LinkStats::PAYLOAD_SIZE, LinkStats::PAYLOAD_MAX},
    {LightsState::ID, LightsState::CRC_EXTRA, LightsState::PAYLOAD_SIZE, LightsState::PAYLOAD_MAX},
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
            out.host_to_mcu = i < HOST_TO_MCU_COUNT;
            return true;
        }
    }
    return false;
}

DispatchResult unpack_host_to_mcu(uint8_t msg_id, const uint8_t* payload, uint8_t len, HostToMcu& m) {
    MessageBounds b;
    if (!message_bounds(msg_id, b)) {
        return DISPATCH_UNKNOWN_ID;
    }
    return unpack_host_to_mcu(b, msg_id, payload, len, m);
}

DispatchResult unpack_host_to_mcu(const MessageBounds& b, uint8_t msg_id, const uint8_t* payload, uint8_t len,
                                 HostToMcu& m) {
    if (!b.host_to_mcu) {
        return DISPATCH_WRONG_DIRECTION;
    }
    if (!layout::copy_payload(payload, len, b.min_payload, b.max_payload, &m)) {
        return DISPATCH_BAD_PAYLOAD;
    }
    bool ok = true;
    if (msg_id == Hello::ID) {
        ok = values_defined(m.hello);
    }
    return ok ? DISPATCH_OK : DISPATCH_BAD_PAYLOAD;
}

DispatchResult unpack_mcu_to_host(uint8_t msg_id, const uint8_t* payload, uint8_t len, McuToHost& m) {
    MessageBounds b;
    if (!message_bounds(msg_id, b)) {
        return DISPATCH_UNKNOWN_ID;
    }
    return unpack_mcu_to_host(b, msg_id, payload, len, m);
}

DispatchResult unpack_mcu_to_host(const MessageBounds& b, uint8_t msg_id, const uint8_t* payload, uint8_t len,
                                 McuToHost& m) {
    if (b.host_to_mcu) {
        return DISPATCH_WRONG_DIRECTION;
    }
    if (!layout::copy_payload(payload, len, b.min_payload, b.max_payload, &m)) {
        return DISPATCH_BAD_PAYLOAD;
    }
    bool ok = true;
    if (msg_id == Identity::ID) {
        ok = values_defined(m.identity);
    } else if (msg_id == Nack::ID) {
        ok = values_defined(m.nack);
    } else if (msg_id == Config::ID) {
        ok = values_defined(m.config);
    } else if (msg_id == LightsState::ID) {
        ok = values_defined(m.lights_state);
    } else if (msg_id == Feedback::ID) {
        ok = values_defined(m.feedback);
    } else if (msg_id == Log::ID) {
        ok = values_defined(m.log);
    }
    return ok ? DISPATCH_OK : DISPATCH_BAD_PAYLOAD;
}

bool values_defined(const Hello& m) {
    // feedback_mode: FeedbackMode
    if (!is_valid_FeedbackMode(static_cast<uint8_t>(m.feedback_mode))) return false;
    return true;
}

uint8_t check_ranges(const Hello& m) {
    // watchdog_ms: 0..60000
    if (m.watchdog_ms > 60000u) return 2;
    // feedback_mode: FeedbackMode
    if (!is_valid_FeedbackMode(static_cast<uint8_t>(m.feedback_mode))) return 3;
    return ALL_FIELDS_VALID;
}

uint8_t check_ranges(const SetPid& m) {
    // kp, ki, kd, kf, ks: 0.0f..1000.0f, as order keys
    for (uint8_t i = 0; i < 5; ++i) {
        float v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(SetPid, kp) + i * sizeof v, sizeof v);
        if (!layout::f32_within(v, 0x7FFFFFFFUL, 0xC47A0000UL)) return static_cast<uint8_t>(1 + i);
    }
    return ALL_FIELDS_VALID;
}

bool values_defined(const SetConfig& m) {
    // safe_state: SafeState
    if (!is_valid_SafeState(static_cast<uint8_t>(m.safe_state))) return false;
    return true;
}

uint8_t check_ranges(const SetConfig& m) {
    // watchdog_ms: 50..2000
    if (m.watchdog_ms < 50u || m.watchdog_ms > 2000u) return 0;
    // safe_state: SafeState
    if (!is_valid_SafeState(static_cast<uint8_t>(m.safe_state))) return 1;
    // accel_limit_mm_s2, decel_limit_mm_s2: 1..65535
    for (uint8_t i = 0; i < 2; ++i) {
        uint16_t v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(SetConfig, accel_limit_mm_s2) + i * sizeof v, sizeof v);
        if (v < 1u) return static_cast<uint8_t>(2 + i);
    }
    // max_wheel_speed_mm_s: 1..20000
    if (m.max_wheel_speed_mm_s < 1u || m.max_wheel_speed_mm_s > 20000u) return 4;
    // max_effort_permille: 0..1000
    if (m.max_effort_permille > 1000u) return 5;
    // encoder_cpr: 1..65535
    if (m.encoder_cpr < 1u) return 6;
    // encoder_invert, motor_invert: 0..3
    for (uint8_t i = 0; i < 2; ++i) {
        uint8_t v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(SetConfig, encoder_invert) + i * sizeof v, sizeof v);
        if (v > 3u) return static_cast<uint8_t>(7 + i);
    }
    // wheel_diameter_um: 1000..1000000
    if (m.wheel_diameter_um < 1000UL || m.wheel_diameter_um > 1000000UL) return 9;
    // steering_center_cdeg, steering_min_cdeg, steering_max_cdeg: 0..18000
    for (uint8_t i = 0; i < 3; ++i) {
        uint16_t v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(SetConfig, steering_center_cdeg) + i * sizeof v, sizeof v);
        if (v > 18000u) return static_cast<uint8_t>(10 + i);
    }
    // steering_step_cdeg: 0..9000
    if (m.steering_step_cdeg > 9000u) return 13;
    // servo_min_us, servo_max_us: 400..2600
    for (uint8_t i = 0; i < 2; ++i) {
        uint16_t v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(SetConfig, servo_min_us) + i * sizeof v, sizeof v);
        if (v < 400u || v > 2600u) return static_cast<uint8_t>(14 + i);
    }
    // esc_min_us, esc_neutral_us, esc_max_us: 800..2200
    for (uint8_t i = 0; i < 3; ++i) {
        uint16_t v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(SetConfig, esc_min_us) + i * sizeof v, sizeof v);
        if (v < 800u || v > 2200u) return static_cast<uint8_t>(16 + i);
    }
    // esc_arm_ms: 0..10000
    if (m.esc_arm_ms > 10000u) return 19;
    // feedback_hz: 1..100
    if (m.feedback_hz < 1u || m.feedback_hz > 100u) return 20;
    return ALL_FIELDS_VALID;
}

bool values_defined(const SetLights& m) {
    // mode: LightsMode
    if (!is_valid_LightsMode(static_cast<uint8_t>(m.mode))) return false;
    return true;
}

uint8_t check_ranges(const SetLights& m) {
    // mode: LightsMode
    if (!is_valid_LightsMode(static_cast<uint8_t>(m.mode))) return 0;
    // steady, slow, fast: 0..15
    for (uint8_t i = 0; i < 3; ++i) {
        uint8_t v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(SetLights, steady) + i * sizeof v, sizeof v);
        if (v > 15u) return static_cast<uint8_t>(1 + i);
    }
    return ALL_FIELDS_VALID;
}

uint8_t check_ranges(const SetAckermann& m) {
    // steering_mrad: -1571..1571
    if (m.steering_mrad < -1571 || m.steering_mrad > 1571) return 1;
    return ALL_FIELDS_VALID;
}

bool values_defined(const Identity& m) {
    // board: Board
    if (!is_valid_Board(static_cast<uint8_t>(m.board))) return false;
    // capabilities: Capability bits 0xFF
    if ((m.capabilities & 0xFF00u) != 0) return false;
    // reason: IdentityReason
    if (!is_valid_IdentityReason(static_cast<uint8_t>(m.reason))) return false;
    // feedback_mode: FeedbackMode
    if (!is_valid_FeedbackMode(static_cast<uint8_t>(m.feedback_mode))) return false;
    // robot_name: ASCII
    for (uint8_t i = 0; i < m.robot_name_len; ++i) {
        const char v = m.robot_name[i];
        if (static_cast<uint8_t>(v) > 0x7F) return false;
    }
    return true;
}

uint8_t check_ranges(const Identity& m) {
    // board: Board
    if (!is_valid_Board(static_cast<uint8_t>(m.board))) return 3;
    // capabilities: Capability bits 0xFF
    if ((m.capabilities & 0xFF00u) != 0) return 4;
    // reason: IdentityReason
    if (!is_valid_IdentityReason(static_cast<uint8_t>(m.reason))) return 7;
    // feedback_mode: FeedbackMode
    if (!is_valid_FeedbackMode(static_cast<uint8_t>(m.feedback_mode))) return 10;
    // robot_name: ASCII
    for (uint8_t i = 0; i < m.robot_name_len; ++i) {
        const char v = m.robot_name[i];
        if (static_cast<uint8_t>(v) > 0x7F) return 12;
    }
    return ALL_FIELDS_VALID;
}

bool values_defined(const Nack& m) {
    // reason: NackReason
    if (!is_valid_NackReason(static_cast<uint8_t>(m.reason))) return false;
    return true;
}

uint8_t check_ranges(const Nack& m) {
    // reason: NackReason
    if (!is_valid_NackReason(static_cast<uint8_t>(m.reason))) return 2;
    return ALL_FIELDS_VALID;
}

uint8_t check_ranges(const Pid& m) {
    // kp, ki, kd, kf, ks: 0.0f..1000.0f, as order keys
    for (uint8_t i = 0; i < 5; ++i) {
        float v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(Pid, kp) + i * sizeof v, sizeof v);
        if (!layout::f32_within(v, 0x7FFFFFFFUL, 0xC47A0000UL)) return static_cast<uint8_t>(2 + i);
    }
    return ALL_FIELDS_VALID;
}

bool values_defined(const Config& m) {
    // safe_state: SafeState
    if (!is_valid_SafeState(static_cast<uint8_t>(m.safe_state))) return false;
    return true;
}

uint8_t check_ranges(const Config& m) {
    // watchdog_ms: 50..2000
    if (m.watchdog_ms < 50u || m.watchdog_ms > 2000u) return 1;
    // safe_state: SafeState
    if (!is_valid_SafeState(static_cast<uint8_t>(m.safe_state))) return 2;
    // accel_limit_mm_s2, decel_limit_mm_s2: 1..65535
    for (uint8_t i = 0; i < 2; ++i) {
        uint16_t v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(Config, accel_limit_mm_s2) + i * sizeof v, sizeof v);
        if (v < 1u) return static_cast<uint8_t>(3 + i);
    }
    // max_wheel_speed_mm_s: 1..20000
    if (m.max_wheel_speed_mm_s < 1u || m.max_wheel_speed_mm_s > 20000u) return 5;
    // max_effort_permille: 0..1000
    if (m.max_effort_permille > 1000u) return 6;
    // encoder_cpr: 1..65535
    if (m.encoder_cpr < 1u) return 7;
    // encoder_invert, motor_invert: 0..3
    for (uint8_t i = 0; i < 2; ++i) {
        uint8_t v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(Config, encoder_invert) + i * sizeof v, sizeof v);
        if (v > 3u) return static_cast<uint8_t>(8 + i);
    }
    // wheel_diameter_um: 1000..1000000
    if (m.wheel_diameter_um < 1000UL || m.wheel_diameter_um > 1000000UL) return 10;
    // steering_center_cdeg, steering_min_cdeg, steering_max_cdeg: 0..18000
    for (uint8_t i = 0; i < 3; ++i) {
        uint16_t v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(Config, steering_center_cdeg) + i * sizeof v, sizeof v);
        if (v > 18000u) return static_cast<uint8_t>(11 + i);
    }
    // steering_step_cdeg: 0..9000
    if (m.steering_step_cdeg > 9000u) return 14;
    // servo_min_us, servo_max_us: 400..2600
    for (uint8_t i = 0; i < 2; ++i) {
        uint16_t v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(Config, servo_min_us) + i * sizeof v, sizeof v);
        if (v < 400u || v > 2600u) return static_cast<uint8_t>(15 + i);
    }
    // esc_min_us, esc_neutral_us, esc_max_us: 800..2200
    for (uint8_t i = 0; i < 3; ++i) {
        uint16_t v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(Config, esc_min_us) + i * sizeof v, sizeof v);
        if (v < 800u || v > 2200u) return static_cast<uint8_t>(17 + i);
    }
    // esc_arm_ms: 0..10000
    if (m.esc_arm_ms > 10000u) return 20;
    // feedback_hz: 1..100
    if (m.feedback_hz < 1u || m.feedback_hz > 100u) return 21;
    return ALL_FIELDS_VALID;
}

bool values_defined(const LightsState& m) {
    // mode: LightsMode
    if (!is_valid_LightsMode(static_cast<uint8_t>(m.mode))) return false;
    return true;
}

uint8_t check_ranges(const LightsState& m) {
    // mode: LightsMode
    if (!is_valid_LightsMode(static_cast<uint8_t>(m.mode))) return 1;
    // steady, slow, fast, lit: 0..15
    for (uint8_t i = 0; i < 4; ++i) {
        uint8_t v;
        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof(LightsState, steady) + i * sizeof v, sizeof v);
        if (v > 15u) return static_cast<uint8_t>(2 + i);
    }
    return ALL_FIELDS_VALID;
}

bool values_defined(const Feedback& m) {
    // status: Status bits 0x7F
    if ((m.status & 0x80u) != 0) return false;
    // failsafe_reason: FailsafeReason
    if (!is_valid_FailsafeReason(static_cast<uint8_t>(m.failsafe_reason))) return false;
    return true;
}

uint8_t check_ranges(const Feedback& m) {
    // status: Status bits 0x7F
    if ((m.status & 0x80u) != 0) return 5;
    // failsafe_reason: FailsafeReason
    if (!is_valid_FailsafeReason(static_cast<uint8_t>(m.failsafe_reason))) return 6;
    // effort_permille: -1000..1000
    for (uint8_t i = 0; i < 2; ++i) {
        const int16_t v = m.effort_permille[i];
        if (v < -1000 || v > 1000) return 9;
    }
    // steering_mrad: -1571..1571
    if (m.steering_mrad < -1571 || m.steering_mrad > 1571) return 10;
    return ALL_FIELDS_VALID;
}

bool values_defined(const Log& m) {
    // level: LogLevel
    if (!is_valid_LogLevel(static_cast<uint8_t>(m.level))) return false;
    // text: ASCII
    for (uint8_t i = 0; i < m.text_len; ++i) {
        const char v = m.text[i];
        if (static_cast<uint8_t>(v) > 0x7F) return false;
    }
    return true;
}

uint8_t check_ranges(const Log& m) {
    // level: LogLevel
    if (!is_valid_LogLevel(static_cast<uint8_t>(m.level))) return 0;
    // text: ASCII
    for (uint8_t i = 0; i < m.text_len; ++i) {
        const char v = m.text[i];
        if (static_cast<uint8_t>(v) > 0x7F) return 1;
    }
    return ALL_FIELDS_VALID;
}

const uint8_t TRANSITIONS[TRANSITION_COUNT][5] ROVERLINK_PROGMEM = {
    {0x01, GUARD_NONE, 1, 0x09, 0x00},  // BOOT INIT_DONE -> IDLE
    {0x02, 1, 2, 0x02, 0x00},  // IDLE HELLO [compatible] -> DISARMED
    {0x02, 1 | GUARD_NEGATED, 1, 0x04, 0x00},  // IDLE HELLO [!compatible] -> IDLE
    {0x1C, 1, 2, 0x8A, 0x00},  // DISARMED|ARMED|FAILSAFE HELLO [compatible] -> DISARMED
    {0x1C, 1 | GUARD_NEGATED, 1, 0x8C, 0x00},  // DISARMED|ARMED|FAILSAFE HELLO [!compatible] -> IDLE
    {0x02, GUARD_NONE, 1, 0x00, 0x02},  // IDLE ARM -> IDLE
    {0x14, 2, 3, 0xB0, 0x01},  // DISARMED|FAILSAFE ARM [boot_id_matches] -> ARMED
    {0x08, 2, 3, 0x20, 0x01},  // ARMED ARM [boot_id_matches] -> ARMED
    {0x1C, 2 | GUARD_NEGATED, TARGET_STAY, 0x00, 0x02},  // DISARMED|ARMED|FAILSAFE ARM [!boot_id_matches] -> (stay)
    {0x02, GUARD_NONE, 1, 0x00, 0x01},  // IDLE DISARM -> IDLE
    {0x1C, GUARD_NONE, 2, 0x88, 0x01},  // DISARMED|ARMED|FAILSAFE DISARM -> DISARMED
    {0x08, GUARD_NONE, 3, 0x00, 0x04},  // ARMED SETPOINT -> ARMED
    {0x16, GUARD_NONE, TARGET_STAY, 0x00, 0x02},  // IDLE|DISARMED|FAILSAFE SETPOINT -> (stay)
    {0x1C, GUARD_NONE, TARGET_STAY, 0x20, 0x00},  // DISARMED|ARMED|FAILSAFE VALID_FRAME -> (stay)
    {0x08, GUARD_NONE, 4, 0x48, 0x00},  // ARMED WATCHDOG_EXPIRED -> FAILSAFE
    {0x0C, GUARD_NONE, 4, 0x48, 0x00},  // ARMED|DISARMED FAULT -> FAILSAFE
    {0x1F, GUARD_NONE, 0, 0x08, 0x00},  // BOOT|IDLE|DISARMED|ARMED|FAILSAFE RESET -> BOOT
};

const uint8_t EVENT_ROWS[EVENT_COUNT + 1] ROVERLINK_PROGMEM = {0, 1, 5, 9, 11, 13, 14, 15, 16, 17};

}  // namespace proto
}  // namespace roverlink
