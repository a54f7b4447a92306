// DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
// spec hash: 0xBDF31659
// Test-only: text view of every message for tests/firmware/native/rl_codec.cpp. Not part of the library.
#ifndef ROVERLINK_REFLECT_H
#define ROVERLINK_REFLECT_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "generated/roverlink_protocol.h"

namespace roverlink {
namespace reflect {

inline void print_f32(FILE* f, float v) {
    uint32_t bits;
    memcpy(&bits, &v, 4);
    fprintf(f, "0x%08lX", static_cast<unsigned long>(bits));
}
inline float parse_f32(const char* s) {
    uint32_t bits = static_cast<uint32_t>(strtoul(s, NULL, 16));
    float v;
    memcpy(&v, &bits, 4);
    return v;
}
inline void print_hex(FILE* f, const uint8_t* p, uint8_t n) {
    for (uint8_t i = 0; i < n; ++i) fprintf(f, "%02x", p[i]);
}
inline uint8_t parse_hex(const char* s, uint8_t* out, uint8_t cap) {
    uint8_t n = 0;
    while (s[0] && s[1] && n < cap) {
        char b[3] = {s[0], s[1], 0};
        out[n++] = static_cast<uint8_t>(strtoul(b, NULL, 16));
        s += 2;
    }
    return n;
}

inline void print_fields(FILE* f, const proto::Hello& m) {
    fputs("HELLO", f);
    fputs(" protocol_version=", f);
    fprintf(f, "%ld", static_cast<long>(m.protocol_version));
    fputs(" spec_hash=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.spec_hash));
    fputs(" watchdog_ms=", f);
    fprintf(f, "%ld", static_cast<long>(m.watchdog_ms));
    fputs(" feedback_mode=", f);
    fprintf(f, "%ld", static_cast<long>(m.feedback_mode));
    fputs(" feedback_hz=", f);
    fprintf(f, "%ld", static_cast<long>(m.feedback_hz));
}

inline bool set_field(proto::Hello& m, const char* name, const char* value) {
    if (strcmp(name, "protocol_version") == 0) {
        const char* v = value;
        m.protocol_version = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "spec_hash") == 0) {
        const char* v = value;
        m.spec_hash = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "watchdog_ms") == 0) {
        const char* v = value;
        m.watchdog_ms = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "feedback_mode") == 0) {
        const char* v = value;
        m.feedback_mode = static_cast<proto::FeedbackMode>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "feedback_hz") == 0) {
        const char* v = value;
        m.feedback_hz = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::Ping& m) {
    fputs("PING", f);
    fputs(" host_time_us=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.host_time_us));
}

inline bool set_field(proto::Ping& m, const char* name, const char* value) {
    if (strcmp(name, "host_time_us") == 0) {
        const char* v = value;
        m.host_time_us = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::Arm& m) {
    fputs("ARM", f);
    fputs(" boot_id=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.boot_id));
}

inline bool set_field(proto::Arm& m, const char* name, const char* value) {
    if (strcmp(name, "boot_id") == 0) {
        const char* v = value;
        m.boot_id = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::Disarm& /*m*/) {
    fputs("DISARM", f);
}

inline bool set_field(proto::Disarm& /*m*/, const char* name, const char* value) {
    (void)name;
    (void)value;
    return false;
}

inline void print_fields(FILE* f, const proto::SetPid& m) {
    fputs("SET_PID", f);
    fputs(" wheel=", f);
    fprintf(f, "%ld", static_cast<long>(m.wheel));
    fputs(" kp=", f);
    print_f32(f, m.kp);
    fputs(" ki=", f);
    print_f32(f, m.ki);
    fputs(" kd=", f);
    print_f32(f, m.kd);
    fputs(" kf=", f);
    print_f32(f, m.kf);
    fputs(" ks=", f);
    print_f32(f, m.ks);
}

inline bool set_field(proto::SetPid& m, const char* name, const char* value) {
    if (strcmp(name, "wheel") == 0) {
        const char* v = value;
        m.wheel = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "kp") == 0) {
        const char* v = value;
        m.kp = parse_f32(v);
        return true;
    }
    if (strcmp(name, "ki") == 0) {
        const char* v = value;
        m.ki = parse_f32(v);
        return true;
    }
    if (strcmp(name, "kd") == 0) {
        const char* v = value;
        m.kd = parse_f32(v);
        return true;
    }
    if (strcmp(name, "kf") == 0) {
        const char* v = value;
        m.kf = parse_f32(v);
        return true;
    }
    if (strcmp(name, "ks") == 0) {
        const char* v = value;
        m.ks = parse_f32(v);
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::GetPid& m) {
    fputs("GET_PID", f);
    fputs(" wheel=", f);
    fprintf(f, "%ld", static_cast<long>(m.wheel));
}

inline bool set_field(proto::GetPid& m, const char* name, const char* value) {
    if (strcmp(name, "wheel") == 0) {
        const char* v = value;
        m.wheel = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::SetConfig& m) {
    fputs("SET_CONFIG", f);
    fputs(" watchdog_ms=", f);
    fprintf(f, "%ld", static_cast<long>(m.watchdog_ms));
    fputs(" safe_state=", f);
    fprintf(f, "%ld", static_cast<long>(m.safe_state));
    fputs(" accel_limit_mm_s2=", f);
    fprintf(f, "%ld", static_cast<long>(m.accel_limit_mm_s2));
    fputs(" decel_limit_mm_s2=", f);
    fprintf(f, "%ld", static_cast<long>(m.decel_limit_mm_s2));
    fputs(" max_wheel_speed_mm_s=", f);
    fprintf(f, "%ld", static_cast<long>(m.max_wheel_speed_mm_s));
    fputs(" max_effort_permille=", f);
    fprintf(f, "%ld", static_cast<long>(m.max_effort_permille));
    fputs(" encoder_cpr=", f);
    fprintf(f, "%ld", static_cast<long>(m.encoder_cpr));
    fputs(" encoder_invert=", f);
    fprintf(f, "%ld", static_cast<long>(m.encoder_invert));
    fputs(" motor_invert=", f);
    fprintf(f, "%ld", static_cast<long>(m.motor_invert));
    fputs(" wheel_diameter_um=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.wheel_diameter_um));
    fputs(" steering_center_cdeg=", f);
    fprintf(f, "%ld", static_cast<long>(m.steering_center_cdeg));
    fputs(" steering_min_cdeg=", f);
    fprintf(f, "%ld", static_cast<long>(m.steering_min_cdeg));
    fputs(" steering_max_cdeg=", f);
    fprintf(f, "%ld", static_cast<long>(m.steering_max_cdeg));
    fputs(" steering_step_cdeg=", f);
    fprintf(f, "%ld", static_cast<long>(m.steering_step_cdeg));
    fputs(" servo_min_us=", f);
    fprintf(f, "%ld", static_cast<long>(m.servo_min_us));
    fputs(" servo_max_us=", f);
    fprintf(f, "%ld", static_cast<long>(m.servo_max_us));
    fputs(" esc_min_us=", f);
    fprintf(f, "%ld", static_cast<long>(m.esc_min_us));
    fputs(" esc_neutral_us=", f);
    fprintf(f, "%ld", static_cast<long>(m.esc_neutral_us));
    fputs(" esc_max_us=", f);
    fprintf(f, "%ld", static_cast<long>(m.esc_max_us));
    fputs(" esc_arm_ms=", f);
    fprintf(f, "%ld", static_cast<long>(m.esc_arm_ms));
    fputs(" feedback_hz=", f);
    fprintf(f, "%ld", static_cast<long>(m.feedback_hz));
}

inline bool set_field(proto::SetConfig& m, const char* name, const char* value) {
    if (strcmp(name, "watchdog_ms") == 0) {
        const char* v = value;
        m.watchdog_ms = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "safe_state") == 0) {
        const char* v = value;
        m.safe_state = static_cast<proto::SafeState>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "accel_limit_mm_s2") == 0) {
        const char* v = value;
        m.accel_limit_mm_s2 = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "decel_limit_mm_s2") == 0) {
        const char* v = value;
        m.decel_limit_mm_s2 = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "max_wheel_speed_mm_s") == 0) {
        const char* v = value;
        m.max_wheel_speed_mm_s = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "max_effort_permille") == 0) {
        const char* v = value;
        m.max_effort_permille = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "encoder_cpr") == 0) {
        const char* v = value;
        m.encoder_cpr = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "encoder_invert") == 0) {
        const char* v = value;
        m.encoder_invert = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "motor_invert") == 0) {
        const char* v = value;
        m.motor_invert = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "wheel_diameter_um") == 0) {
        const char* v = value;
        m.wheel_diameter_um = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "steering_center_cdeg") == 0) {
        const char* v = value;
        m.steering_center_cdeg = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "steering_min_cdeg") == 0) {
        const char* v = value;
        m.steering_min_cdeg = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "steering_max_cdeg") == 0) {
        const char* v = value;
        m.steering_max_cdeg = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "steering_step_cdeg") == 0) {
        const char* v = value;
        m.steering_step_cdeg = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "servo_min_us") == 0) {
        const char* v = value;
        m.servo_min_us = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "servo_max_us") == 0) {
        const char* v = value;
        m.servo_max_us = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "esc_min_us") == 0) {
        const char* v = value;
        m.esc_min_us = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "esc_neutral_us") == 0) {
        const char* v = value;
        m.esc_neutral_us = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "esc_max_us") == 0) {
        const char* v = value;
        m.esc_max_us = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "esc_arm_ms") == 0) {
        const char* v = value;
        m.esc_arm_ms = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "feedback_hz") == 0) {
        const char* v = value;
        m.feedback_hz = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::GetConfig& /*m*/) {
    fputs("GET_CONFIG", f);
}

inline bool set_field(proto::GetConfig& /*m*/, const char* name, const char* value) {
    (void)name;
    (void)value;
    return false;
}

inline void print_fields(FILE* f, const proto::SaveConfig& /*m*/) {
    fputs("SAVE_CONFIG", f);
}

inline bool set_field(proto::SaveConfig& /*m*/, const char* name, const char* value) {
    (void)name;
    (void)value;
    return false;
}

inline void print_fields(FILE* f, const proto::ResetOdometry& /*m*/) {
    fputs("RESET_ODOMETRY", f);
}

inline bool set_field(proto::ResetOdometry& /*m*/, const char* name, const char* value) {
    (void)name;
    (void)value;
    return false;
}

inline void print_fields(FILE* f, const proto::GetLinkStats& /*m*/) {
    fputs("GET_LINK_STATS", f);
}

inline bool set_field(proto::GetLinkStats& /*m*/, const char* name, const char* value) {
    (void)name;
    (void)value;
    return false;
}

inline void print_fields(FILE* f, const proto::SetLights& m) {
    fputs("SET_LIGHTS", f);
    fputs(" mode=", f);
    fprintf(f, "%ld", static_cast<long>(m.mode));
    fputs(" steady=", f);
    fprintf(f, "%ld", static_cast<long>(m.steady));
    fputs(" slow=", f);
    fprintf(f, "%ld", static_cast<long>(m.slow));
    fputs(" fast=", f);
    fprintf(f, "%ld", static_cast<long>(m.fast));
}

inline bool set_field(proto::SetLights& m, const char* name, const char* value) {
    if (strcmp(name, "mode") == 0) {
        const char* v = value;
        m.mode = static_cast<proto::LightsMode>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "steady") == 0) {
        const char* v = value;
        m.steady = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "slow") == 0) {
        const char* v = value;
        m.slow = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "fast") == 0) {
        const char* v = value;
        m.fast = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::GetLights& /*m*/) {
    fputs("GET_LIGHTS", f);
}

inline bool set_field(proto::GetLights& /*m*/, const char* name, const char* value) {
    (void)name;
    (void)value;
    return false;
}

inline void print_fields(FILE* f, const proto::SetWheelSpeeds& m) {
    fputs("SET_WHEEL_SPEEDS", f);
    fputs(" left_mm_s=", f);
    fprintf(f, "%ld", static_cast<long>(m.left_mm_s));
    fputs(" right_mm_s=", f);
    fprintf(f, "%ld", static_cast<long>(m.right_mm_s));
}

inline bool set_field(proto::SetWheelSpeeds& m, const char* name, const char* value) {
    if (strcmp(name, "left_mm_s") == 0) {
        const char* v = value;
        m.left_mm_s = static_cast<int16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "right_mm_s") == 0) {
        const char* v = value;
        m.right_mm_s = static_cast<int16_t>(strtol(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::SetAckermann& m) {
    fputs("SET_ACKERMANN", f);
    fputs(" speed_mm_s=", f);
    fprintf(f, "%ld", static_cast<long>(m.speed_mm_s));
    fputs(" steering_mrad=", f);
    fprintf(f, "%ld", static_cast<long>(m.steering_mrad));
}

inline bool set_field(proto::SetAckermann& m, const char* name, const char* value) {
    if (strcmp(name, "speed_mm_s") == 0) {
        const char* v = value;
        m.speed_mm_s = static_cast<int16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "steering_mrad") == 0) {
        const char* v = value;
        m.steering_mrad = static_cast<int16_t>(strtol(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::Identity& m) {
    fputs("IDENTITY", f);
    fputs(" protocol_version=", f);
    fprintf(f, "%ld", static_cast<long>(m.protocol_version));
    fputs(" spec_hash=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.spec_hash));
    fputs(" firmware_version=", f);
    for (uint8_t k = 0; k < 3; ++k) {
        if (k) fputc(',', f);
        fprintf(f, "%ld", static_cast<long>(m.firmware_version[k]));
    }
    fputs(" board=", f);
    fprintf(f, "%ld", static_cast<long>(m.board));
    fputs(" capabilities=", f);
    fprintf(f, "%ld", static_cast<long>(m.capabilities));
    fputs(" boot_id=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.boot_id));
    fputs(" uptime_ms=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.uptime_ms));
    fputs(" reason=", f);
    fprintf(f, "%ld", static_cast<long>(m.reason));
    fputs(" hello_seq=", f);
    fprintf(f, "%ld", static_cast<long>(m.hello_seq));
    fputs(" watchdog_ms=", f);
    fprintf(f, "%ld", static_cast<long>(m.watchdog_ms));
    fputs(" feedback_mode=", f);
    fprintf(f, "%ld", static_cast<long>(m.feedback_mode));
    fputs(" feedback_hz=", f);
    fprintf(f, "%ld", static_cast<long>(m.feedback_hz));
    fputs(" robot_name=", f);
    print_hex(f, reinterpret_cast<const uint8_t*>(m.robot_name), m.robot_name_len);
}

inline bool set_field(proto::Identity& m, const char* name, const char* value) {
    if (strcmp(name, "protocol_version") == 0) {
        const char* v = value;
        m.protocol_version = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "spec_hash") == 0) {
        const char* v = value;
        m.spec_hash = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "firmware_version") == 0) {
        const char* v = value;
        for (uint8_t k = 0; k < 3; ++k) {
            m.firmware_version[k] = static_cast<uint8_t>(strtol(v, NULL, 10));
            v = strchr(v, ',');
            if (!v) return k == 2;
            ++v;
        }
        return true;
    }
    if (strcmp(name, "board") == 0) {
        const char* v = value;
        m.board = static_cast<proto::Board>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "capabilities") == 0) {
        const char* v = value;
        m.capabilities = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "boot_id") == 0) {
        const char* v = value;
        m.boot_id = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "uptime_ms") == 0) {
        const char* v = value;
        m.uptime_ms = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "reason") == 0) {
        const char* v = value;
        m.reason = static_cast<proto::IdentityReason>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "hello_seq") == 0) {
        const char* v = value;
        m.hello_seq = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "watchdog_ms") == 0) {
        const char* v = value;
        m.watchdog_ms = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "feedback_mode") == 0) {
        const char* v = value;
        m.feedback_mode = static_cast<proto::FeedbackMode>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "feedback_hz") == 0) {
        const char* v = value;
        m.feedback_hz = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "robot_name") == 0) {
        m.robot_name_len = parse_hex(value, reinterpret_cast<uint8_t*>(m.robot_name), 24);
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::Pong& m) {
    fputs("PONG", f);
    fputs(" host_time_us=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.host_time_us));
    fputs(" mcu_time_us=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.mcu_time_us));
}

inline bool set_field(proto::Pong& m, const char* name, const char* value) {
    if (strcmp(name, "host_time_us") == 0) {
        const char* v = value;
        m.host_time_us = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "mcu_time_us") == 0) {
        const char* v = value;
        m.mcu_time_us = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::Ack& m) {
    fputs("ACK", f);
    fputs(" req_id=", f);
    fprintf(f, "%ld", static_cast<long>(m.req_id));
    fputs(" req_seq=", f);
    fprintf(f, "%ld", static_cast<long>(m.req_seq));
}

inline bool set_field(proto::Ack& m, const char* name, const char* value) {
    if (strcmp(name, "req_id") == 0) {
        const char* v = value;
        m.req_id = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "req_seq") == 0) {
        const char* v = value;
        m.req_seq = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::Nack& m) {
    fputs("NACK", f);
    fputs(" req_id=", f);
    fprintf(f, "%ld", static_cast<long>(m.req_id));
    fputs(" req_seq=", f);
    fprintf(f, "%ld", static_cast<long>(m.req_seq));
    fputs(" reason=", f);
    fprintf(f, "%ld", static_cast<long>(m.reason));
    fputs(" detail=", f);
    fprintf(f, "%ld", static_cast<long>(m.detail));
}

inline bool set_field(proto::Nack& m, const char* name, const char* value) {
    if (strcmp(name, "req_id") == 0) {
        const char* v = value;
        m.req_id = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "req_seq") == 0) {
        const char* v = value;
        m.req_seq = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "reason") == 0) {
        const char* v = value;
        m.reason = static_cast<proto::NackReason>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "detail") == 0) {
        const char* v = value;
        m.detail = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::Pid& m) {
    fputs("PID", f);
    fputs(" req_seq=", f);
    fprintf(f, "%ld", static_cast<long>(m.req_seq));
    fputs(" wheel=", f);
    fprintf(f, "%ld", static_cast<long>(m.wheel));
    fputs(" kp=", f);
    print_f32(f, m.kp);
    fputs(" ki=", f);
    print_f32(f, m.ki);
    fputs(" kd=", f);
    print_f32(f, m.kd);
    fputs(" kf=", f);
    print_f32(f, m.kf);
    fputs(" ks=", f);
    print_f32(f, m.ks);
}

inline bool set_field(proto::Pid& m, const char* name, const char* value) {
    if (strcmp(name, "req_seq") == 0) {
        const char* v = value;
        m.req_seq = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "wheel") == 0) {
        const char* v = value;
        m.wheel = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "kp") == 0) {
        const char* v = value;
        m.kp = parse_f32(v);
        return true;
    }
    if (strcmp(name, "ki") == 0) {
        const char* v = value;
        m.ki = parse_f32(v);
        return true;
    }
    if (strcmp(name, "kd") == 0) {
        const char* v = value;
        m.kd = parse_f32(v);
        return true;
    }
    if (strcmp(name, "kf") == 0) {
        const char* v = value;
        m.kf = parse_f32(v);
        return true;
    }
    if (strcmp(name, "ks") == 0) {
        const char* v = value;
        m.ks = parse_f32(v);
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::Config& m) {
    fputs("CONFIG", f);
    fputs(" req_seq=", f);
    fprintf(f, "%ld", static_cast<long>(m.req_seq));
    fputs(" watchdog_ms=", f);
    fprintf(f, "%ld", static_cast<long>(m.watchdog_ms));
    fputs(" safe_state=", f);
    fprintf(f, "%ld", static_cast<long>(m.safe_state));
    fputs(" accel_limit_mm_s2=", f);
    fprintf(f, "%ld", static_cast<long>(m.accel_limit_mm_s2));
    fputs(" decel_limit_mm_s2=", f);
    fprintf(f, "%ld", static_cast<long>(m.decel_limit_mm_s2));
    fputs(" max_wheel_speed_mm_s=", f);
    fprintf(f, "%ld", static_cast<long>(m.max_wheel_speed_mm_s));
    fputs(" max_effort_permille=", f);
    fprintf(f, "%ld", static_cast<long>(m.max_effort_permille));
    fputs(" encoder_cpr=", f);
    fprintf(f, "%ld", static_cast<long>(m.encoder_cpr));
    fputs(" encoder_invert=", f);
    fprintf(f, "%ld", static_cast<long>(m.encoder_invert));
    fputs(" motor_invert=", f);
    fprintf(f, "%ld", static_cast<long>(m.motor_invert));
    fputs(" wheel_diameter_um=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.wheel_diameter_um));
    fputs(" steering_center_cdeg=", f);
    fprintf(f, "%ld", static_cast<long>(m.steering_center_cdeg));
    fputs(" steering_min_cdeg=", f);
    fprintf(f, "%ld", static_cast<long>(m.steering_min_cdeg));
    fputs(" steering_max_cdeg=", f);
    fprintf(f, "%ld", static_cast<long>(m.steering_max_cdeg));
    fputs(" steering_step_cdeg=", f);
    fprintf(f, "%ld", static_cast<long>(m.steering_step_cdeg));
    fputs(" servo_min_us=", f);
    fprintf(f, "%ld", static_cast<long>(m.servo_min_us));
    fputs(" servo_max_us=", f);
    fprintf(f, "%ld", static_cast<long>(m.servo_max_us));
    fputs(" esc_min_us=", f);
    fprintf(f, "%ld", static_cast<long>(m.esc_min_us));
    fputs(" esc_neutral_us=", f);
    fprintf(f, "%ld", static_cast<long>(m.esc_neutral_us));
    fputs(" esc_max_us=", f);
    fprintf(f, "%ld", static_cast<long>(m.esc_max_us));
    fputs(" esc_arm_ms=", f);
    fprintf(f, "%ld", static_cast<long>(m.esc_arm_ms));
    fputs(" feedback_hz=", f);
    fprintf(f, "%ld", static_cast<long>(m.feedback_hz));
}

inline bool set_field(proto::Config& m, const char* name, const char* value) {
    if (strcmp(name, "req_seq") == 0) {
        const char* v = value;
        m.req_seq = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "watchdog_ms") == 0) {
        const char* v = value;
        m.watchdog_ms = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "safe_state") == 0) {
        const char* v = value;
        m.safe_state = static_cast<proto::SafeState>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "accel_limit_mm_s2") == 0) {
        const char* v = value;
        m.accel_limit_mm_s2 = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "decel_limit_mm_s2") == 0) {
        const char* v = value;
        m.decel_limit_mm_s2 = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "max_wheel_speed_mm_s") == 0) {
        const char* v = value;
        m.max_wheel_speed_mm_s = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "max_effort_permille") == 0) {
        const char* v = value;
        m.max_effort_permille = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "encoder_cpr") == 0) {
        const char* v = value;
        m.encoder_cpr = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "encoder_invert") == 0) {
        const char* v = value;
        m.encoder_invert = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "motor_invert") == 0) {
        const char* v = value;
        m.motor_invert = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "wheel_diameter_um") == 0) {
        const char* v = value;
        m.wheel_diameter_um = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "steering_center_cdeg") == 0) {
        const char* v = value;
        m.steering_center_cdeg = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "steering_min_cdeg") == 0) {
        const char* v = value;
        m.steering_min_cdeg = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "steering_max_cdeg") == 0) {
        const char* v = value;
        m.steering_max_cdeg = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "steering_step_cdeg") == 0) {
        const char* v = value;
        m.steering_step_cdeg = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "servo_min_us") == 0) {
        const char* v = value;
        m.servo_min_us = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "servo_max_us") == 0) {
        const char* v = value;
        m.servo_max_us = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "esc_min_us") == 0) {
        const char* v = value;
        m.esc_min_us = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "esc_neutral_us") == 0) {
        const char* v = value;
        m.esc_neutral_us = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "esc_max_us") == 0) {
        const char* v = value;
        m.esc_max_us = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "esc_arm_ms") == 0) {
        const char* v = value;
        m.esc_arm_ms = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "feedback_hz") == 0) {
        const char* v = value;
        m.feedback_hz = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::LinkStats& m) {
    fputs("LINK_STATS", f);
    fputs(" req_seq=", f);
    fprintf(f, "%ld", static_cast<long>(m.req_seq));
    fputs(" frames_ok=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.frames_ok));
    fputs(" crc_errors=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.crc_errors));
    fputs(" cobs_errors=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.cobs_errors));
    fputs(" length_errors=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.length_errors));
    fputs(" unknown_ids=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.unknown_ids));
    fputs(" value_errors=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.value_errors));
    fputs(" bytes_discarded=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.bytes_discarded));
    fputs(" seq_gaps=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.seq_gaps));
    fputs(" duplicates=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.duplicates));
    fputs(" frames_sent=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.frames_sent));
    fputs(" rx_overruns=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.rx_overruns));
}

inline bool set_field(proto::LinkStats& m, const char* name, const char* value) {
    if (strcmp(name, "req_seq") == 0) {
        const char* v = value;
        m.req_seq = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "frames_ok") == 0) {
        const char* v = value;
        m.frames_ok = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "crc_errors") == 0) {
        const char* v = value;
        m.crc_errors = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "cobs_errors") == 0) {
        const char* v = value;
        m.cobs_errors = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "length_errors") == 0) {
        const char* v = value;
        m.length_errors = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "unknown_ids") == 0) {
        const char* v = value;
        m.unknown_ids = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "value_errors") == 0) {
        const char* v = value;
        m.value_errors = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "bytes_discarded") == 0) {
        const char* v = value;
        m.bytes_discarded = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "seq_gaps") == 0) {
        const char* v = value;
        m.seq_gaps = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "duplicates") == 0) {
        const char* v = value;
        m.duplicates = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "frames_sent") == 0) {
        const char* v = value;
        m.frames_sent = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "rx_overruns") == 0) {
        const char* v = value;
        m.rx_overruns = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::LightsState& m) {
    fputs("LIGHTS_STATE", f);
    fputs(" req_seq=", f);
    fprintf(f, "%ld", static_cast<long>(m.req_seq));
    fputs(" mode=", f);
    fprintf(f, "%ld", static_cast<long>(m.mode));
    fputs(" steady=", f);
    fprintf(f, "%ld", static_cast<long>(m.steady));
    fputs(" slow=", f);
    fprintf(f, "%ld", static_cast<long>(m.slow));
    fputs(" fast=", f);
    fprintf(f, "%ld", static_cast<long>(m.fast));
    fputs(" lit=", f);
    fprintf(f, "%ld", static_cast<long>(m.lit));
}

inline bool set_field(proto::LightsState& m, const char* name, const char* value) {
    if (strcmp(name, "req_seq") == 0) {
        const char* v = value;
        m.req_seq = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "mode") == 0) {
        const char* v = value;
        m.mode = static_cast<proto::LightsMode>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "steady") == 0) {
        const char* v = value;
        m.steady = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "slow") == 0) {
        const char* v = value;
        m.slow = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "fast") == 0) {
        const char* v = value;
        m.fast = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "lit") == 0) {
        const char* v = value;
        m.lit = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::Feedback& m) {
    fputs("FEEDBACK", f);
    fputs(" boot_id=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.boot_id));
    fputs(" mcu_time_us=", f);
    fprintf(f, "%lu", static_cast<unsigned long>(m.mcu_time_us));
    fputs(" tick=", f);
    fprintf(f, "%ld", static_cast<long>(m.tick));
    fputs(" ack_seq=", f);
    fprintf(f, "%ld", static_cast<long>(m.ack_seq));
    fputs(" ack_tick=", f);
    fprintf(f, "%ld", static_cast<long>(m.ack_tick));
    fputs(" status=", f);
    fprintf(f, "%ld", static_cast<long>(m.status));
    fputs(" failsafe_reason=", f);
    fprintf(f, "%ld", static_cast<long>(m.failsafe_reason));
    fputs(" encoder_counts=", f);
    for (uint8_t k = 0; k < 2; ++k) {
        if (k) fputc(',', f);
        fprintf(f, "%ld", static_cast<long>(m.encoder_counts[k]));
    }
    fputs(" wheel_speed_mm_s=", f);
    for (uint8_t k = 0; k < 2; ++k) {
        if (k) fputc(',', f);
        fprintf(f, "%ld", static_cast<long>(m.wheel_speed_mm_s[k]));
    }
    fputs(" effort_permille=", f);
    for (uint8_t k = 0; k < 2; ++k) {
        if (k) fputc(',', f);
        fprintf(f, "%ld", static_cast<long>(m.effort_permille[k]));
    }
    fputs(" steering_mrad=", f);
    fprintf(f, "%ld", static_cast<long>(m.steering_mrad));
}

inline bool set_field(proto::Feedback& m, const char* name, const char* value) {
    if (strcmp(name, "boot_id") == 0) {
        const char* v = value;
        m.boot_id = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "mcu_time_us") == 0) {
        const char* v = value;
        m.mcu_time_us = static_cast<uint32_t>(strtoul(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "tick") == 0) {
        const char* v = value;
        m.tick = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "ack_seq") == 0) {
        const char* v = value;
        m.ack_seq = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "ack_tick") == 0) {
        const char* v = value;
        m.ack_tick = static_cast<uint16_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "status") == 0) {
        const char* v = value;
        m.status = static_cast<uint8_t>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "failsafe_reason") == 0) {
        const char* v = value;
        m.failsafe_reason = static_cast<proto::FailsafeReason>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "encoder_counts") == 0) {
        const char* v = value;
        for (uint8_t k = 0; k < 2; ++k) {
            m.encoder_counts[k] = static_cast<int32_t>(strtol(v, NULL, 10));
            v = strchr(v, ',');
            if (!v) return k == 1;
            ++v;
        }
        return true;
    }
    if (strcmp(name, "wheel_speed_mm_s") == 0) {
        const char* v = value;
        for (uint8_t k = 0; k < 2; ++k) {
            m.wheel_speed_mm_s[k] = static_cast<int16_t>(strtol(v, NULL, 10));
            v = strchr(v, ',');
            if (!v) return k == 1;
            ++v;
        }
        return true;
    }
    if (strcmp(name, "effort_permille") == 0) {
        const char* v = value;
        for (uint8_t k = 0; k < 2; ++k) {
            m.effort_permille[k] = static_cast<int16_t>(strtol(v, NULL, 10));
            v = strchr(v, ',');
            if (!v) return k == 1;
            ++v;
        }
        return true;
    }
    if (strcmp(name, "steering_mrad") == 0) {
        const char* v = value;
        m.steering_mrad = static_cast<int16_t>(strtol(v, NULL, 10));
        return true;
    }
    return false;
}

inline void print_fields(FILE* f, const proto::Log& m) {
    fputs("LOG", f);
    fputs(" level=", f);
    fprintf(f, "%ld", static_cast<long>(m.level));
    fputs(" text=", f);
    print_hex(f, reinterpret_cast<const uint8_t*>(m.text), m.text_len);
}

inline bool set_field(proto::Log& m, const char* name, const char* value) {
    if (strcmp(name, "level") == 0) {
        const char* v = value;
        m.level = static_cast<proto::LogLevel>(strtol(v, NULL, 10));
        return true;
    }
    if (strcmp(name, "text") == 0) {
        m.text_len = parse_hex(value, reinterpret_cast<uint8_t*>(m.text), 60);
        return true;
    }
    return false;
}

// A DecoderCounters's fields only (no name), e.g. " frames_ok=0 ...".
inline void print_fields(FILE* f, const proto::DecoderCounters& s) {
    fprintf(f, " frames_ok=%lu", static_cast<unsigned long>(s.frames_ok));
    fprintf(f, " crc_errors=%lu", static_cast<unsigned long>(s.crc_errors));
    fprintf(f, " cobs_errors=%lu", static_cast<unsigned long>(s.cobs_errors));
    fprintf(f, " length_errors=%lu", static_cast<unsigned long>(s.length_errors));
    fprintf(f, " unknown_ids=%lu", static_cast<unsigned long>(s.unknown_ids));
    fprintf(f, " value_errors=%lu", static_cast<unsigned long>(s.value_errors));
    fprintf(f, " bytes_discarded=%lu", static_cast<unsigned long>(s.bytes_discarded));
}

// A LinkCounters's fields only (no name), e.g. " seq_gaps=0 ...".
inline void print_fields(FILE* f, const proto::LinkCounters& s) {
    fprintf(f, " seq_gaps=%lu", static_cast<unsigned long>(s.seq_gaps));
    fprintf(f, " duplicates=%lu", static_cast<unsigned long>(s.duplicates));
    fprintf(f, " frames_sent=%lu", static_cast<unsigned long>(s.frames_sent));
    fprintf(f, " rx_overruns=%lu", static_cast<unsigned long>(s.rx_overruns));
}

// Calls fn(msg) with a zeroed message of type `msg_id`; false for an unknown id.
template <class Fn>
bool with_message(uint8_t msg_id, Fn& fn) {
    switch (msg_id) {
    case proto::Hello::ID: {
        proto::Hello m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::Ping::ID: {
        proto::Ping m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::Arm::ID: {
        proto::Arm m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::Disarm::ID: {
        proto::Disarm m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::SetPid::ID: {
        proto::SetPid m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::GetPid::ID: {
        proto::GetPid m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::SetConfig::ID: {
        proto::SetConfig m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::GetConfig::ID: {
        proto::GetConfig m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::SaveConfig::ID: {
        proto::SaveConfig m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::ResetOdometry::ID: {
        proto::ResetOdometry m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::GetLinkStats::ID: {
        proto::GetLinkStats m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::SetLights::ID: {
        proto::SetLights m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::GetLights::ID: {
        proto::GetLights m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::SetWheelSpeeds::ID: {
        proto::SetWheelSpeeds m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::SetAckermann::ID: {
        proto::SetAckermann m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::Identity::ID: {
        proto::Identity m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::Pong::ID: {
        proto::Pong m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::Ack::ID: {
        proto::Ack m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::Nack::ID: {
        proto::Nack m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::Pid::ID: {
        proto::Pid m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::Config::ID: {
        proto::Config m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::LinkStats::ID: {
        proto::LinkStats m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::LightsState::ID: {
        proto::LightsState m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::Feedback::ID: {
        proto::Feedback m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    case proto::Log::ID: {
        proto::Log m;
        memset(&m, 0, sizeof m);
        fn(m);
        return true;
    }
    default:
        return false;
    }
}

// msg_id of a message NAME, or -1.
inline int id_of(const char* name) {
    if (strcmp(name, "HELLO") == 0) return proto::Hello::ID;
    if (strcmp(name, "PING") == 0) return proto::Ping::ID;
    if (strcmp(name, "ARM") == 0) return proto::Arm::ID;
    if (strcmp(name, "DISARM") == 0) return proto::Disarm::ID;
    if (strcmp(name, "SET_PID") == 0) return proto::SetPid::ID;
    if (strcmp(name, "GET_PID") == 0) return proto::GetPid::ID;
    if (strcmp(name, "SET_CONFIG") == 0) return proto::SetConfig::ID;
    if (strcmp(name, "GET_CONFIG") == 0) return proto::GetConfig::ID;
    if (strcmp(name, "SAVE_CONFIG") == 0) return proto::SaveConfig::ID;
    if (strcmp(name, "RESET_ODOMETRY") == 0) return proto::ResetOdometry::ID;
    if (strcmp(name, "GET_LINK_STATS") == 0) return proto::GetLinkStats::ID;
    if (strcmp(name, "SET_LIGHTS") == 0) return proto::SetLights::ID;
    if (strcmp(name, "GET_LIGHTS") == 0) return proto::GetLights::ID;
    if (strcmp(name, "SET_WHEEL_SPEEDS") == 0) return proto::SetWheelSpeeds::ID;
    if (strcmp(name, "SET_ACKERMANN") == 0) return proto::SetAckermann::ID;
    if (strcmp(name, "IDENTITY") == 0) return proto::Identity::ID;
    if (strcmp(name, "PONG") == 0) return proto::Pong::ID;
    if (strcmp(name, "ACK") == 0) return proto::Ack::ID;
    if (strcmp(name, "NACK") == 0) return proto::Nack::ID;
    if (strcmp(name, "PID") == 0) return proto::Pid::ID;
    if (strcmp(name, "CONFIG") == 0) return proto::Config::ID;
    if (strcmp(name, "LINK_STATS") == 0) return proto::LinkStats::ID;
    if (strcmp(name, "LIGHTS_STATE") == 0) return proto::LightsState::ID;
    if (strcmp(name, "FEEDBACK") == 0) return proto::Feedback::ID;
    if (strcmp(name, "LOG") == 0) return proto::Log::ID;
    return -1;
}

}  // namespace reflect
}  // namespace roverlink

#endif  // ROVERLINK_REFLECT_H
