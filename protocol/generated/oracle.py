# DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
# spec hash: 0xBDF31659
"""construct declarations of every payload: an independent oracle for the codec in tests,
and the field-by-field view behind `roverlink decode`."""

from typing import Any

from construct import Array, Bytes, GreedyBytes, Int16ul, Struct, Int8ul  # noqa: F401
from construct import Float32l, Int8sl, Int16sl, Int32sl, Int32ul  # noqa: F401

BODY: Any = Struct("msg_id" / Int8ul, "seq" / Int8ul, "rest" / GreedyBytes)
"""Decoded frame body; the last two bytes of `rest` are the CRC (little-endian)."""

PAYLOADS: dict[int, Any] = {
    0x01: Struct("protocol_version" / Int8ul, "spec_hash" / Int32ul, "watchdog_ms" / Int16ul, "feedback_mode" / Int8ul, "feedback_hz" / Int8ul),  # HELLO
    0x02: Struct("host_time_us" / Int32ul),  # PING
    0x10: Struct("boot_id" / Int32ul),  # ARM
    0x11: Struct(),  # DISARM
    0x12: Struct("wheel" / Int8ul, "kp" / Float32l, "ki" / Float32l, "kd" / Float32l, "kf" / Float32l, "ks" / Float32l),  # SET_PID
    0x13: Struct("wheel" / Int8ul),  # GET_PID
    0x14: Struct("watchdog_ms" / Int16ul, "safe_state" / Int8ul, "accel_limit_mm_s2" / Int16ul, "decel_limit_mm_s2" / Int16ul, "max_wheel_speed_mm_s" / Int16ul, "max_effort_permille" / Int16ul, "encoder_cpr" / Int16ul, "encoder_invert" / Int8ul, "motor_invert" / Int8ul, "wheel_diameter_um" / Int32ul, "steering_center_cdeg" / Int16ul, "steering_min_cdeg" / Int16ul, "steering_max_cdeg" / Int16ul, "steering_step_cdeg" / Int16ul, "servo_min_us" / Int16ul, "servo_max_us" / Int16ul, "esc_min_us" / Int16ul, "esc_neutral_us" / Int16ul, "esc_max_us" / Int16ul, "esc_arm_ms" / Int16ul, "feedback_hz" / Int8ul),  # SET_CONFIG
    0x15: Struct(),  # GET_CONFIG
    0x16: Struct(),  # SAVE_CONFIG
    0x17: Struct(),  # RESET_ODOMETRY
    0x18: Struct(),  # GET_LINK_STATS
    0x19: Struct("mode" / Int8ul, "steady" / Int8ul, "slow" / Int8ul, "fast" / Int8ul),  # SET_LIGHTS
    0x1A: Struct(),  # GET_LIGHTS
    0x20: Struct("left_mm_s" / Int16sl, "right_mm_s" / Int16sl),  # SET_WHEEL_SPEEDS
    0x21: Struct("speed_mm_s" / Int16sl, "steering_mrad" / Int16sl),  # SET_ACKERMANN
    0x81: Struct("protocol_version" / Int8ul, "spec_hash" / Int32ul, "firmware_version" / Array(3, Int8ul), "board" / Int8ul, "capabilities" / Int16ul, "boot_id" / Int32ul, "uptime_ms" / Int32ul, "reason" / Int8ul, "hello_seq" / Int8ul, "watchdog_ms" / Int16ul, "feedback_mode" / Int8ul, "feedback_hz" / Int8ul, "robot_name" / GreedyBytes),  # IDENTITY
    0x82: Struct("host_time_us" / Int32ul, "mcu_time_us" / Int32ul),  # PONG
    0x83: Struct("req_id" / Int8ul, "req_seq" / Int8ul),  # ACK
    0x84: Struct("req_id" / Int8ul, "req_seq" / Int8ul, "reason" / Int8ul, "detail" / Int8ul),  # NACK
    0x85: Struct("req_seq" / Int8ul, "wheel" / Int8ul, "kp" / Float32l, "ki" / Float32l, "kd" / Float32l, "kf" / Float32l, "ks" / Float32l),  # PID
    0x86: Struct("req_seq" / Int8ul, "watchdog_ms" / Int16ul, "safe_state" / Int8ul, "accel_limit_mm_s2" / Int16ul, "decel_limit_mm_s2" / Int16ul, "max_wheel_speed_mm_s" / Int16ul, "max_effort_permille" / Int16ul, "encoder_cpr" / Int16ul, "encoder_invert" / Int8ul, "motor_invert" / Int8ul, "wheel_diameter_um" / Int32ul, "steering_center_cdeg" / Int16ul, "steering_min_cdeg" / Int16ul, "steering_max_cdeg" / Int16ul, "steering_step_cdeg" / Int16ul, "servo_min_us" / Int16ul, "servo_max_us" / Int16ul, "esc_min_us" / Int16ul, "esc_neutral_us" / Int16ul, "esc_max_us" / Int16ul, "esc_arm_ms" / Int16ul, "feedback_hz" / Int8ul),  # CONFIG
    0x87: Struct("req_seq" / Int8ul, "frames_ok" / Int32ul, "crc_errors" / Int32ul, "cobs_errors" / Int32ul, "length_errors" / Int32ul, "unknown_ids" / Int32ul, "value_errors" / Int32ul, "bytes_discarded" / Int32ul, "seq_gaps" / Int32ul, "duplicates" / Int32ul, "frames_sent" / Int32ul, "rx_overruns" / Int32ul),  # LINK_STATS
    0x88: Struct("req_seq" / Int8ul, "mode" / Int8ul, "steady" / Int8ul, "slow" / Int8ul, "fast" / Int8ul, "lit" / Int8ul),  # LIGHTS_STATE
    0x90: Struct("boot_id" / Int32ul, "mcu_time_us" / Int32ul, "tick" / Int16ul, "ack_seq" / Int8ul, "ack_tick" / Int16ul, "status" / Int8ul, "failsafe_reason" / Int8ul, "encoder_counts" / Array(2, Int32sl), "wheel_speed_mm_s" / Array(2, Int16sl), "effort_permille" / Array(2, Int16sl), "steering_mrad" / Int16sl),  # FEEDBACK
    0x91: Struct("level" / Int8ul, "text" / GreedyBytes),  # LOG
}

NAMES: dict[int, str] = {
    0x01: "HELLO",
    0x02: "PING",
    0x10: "ARM",
    0x11: "DISARM",
    0x12: "SET_PID",
    0x13: "GET_PID",
    0x14: "SET_CONFIG",
    0x15: "GET_CONFIG",
    0x16: "SAVE_CONFIG",
    0x17: "RESET_ODOMETRY",
    0x18: "GET_LINK_STATS",
    0x19: "SET_LIGHTS",
    0x1A: "GET_LIGHTS",
    0x20: "SET_WHEEL_SPEEDS",
    0x21: "SET_ACKERMANN",
    0x81: "IDENTITY",
    0x82: "PONG",
    0x83: "ACK",
    0x84: "NACK",
    0x85: "PID",
    0x86: "CONFIG",
    0x87: "LINK_STATS",
    0x88: "LIGHTS_STATE",
    0x90: "FEEDBACK",
    0x91: "LOG",
}

CRC_EXTRA: dict[int, int] = {
    0x01: 0x77,
    0x02: 0x8B,
    0x10: 0x2A,
    0x11: 0x95,
    0x12: 0x34,
    0x13: 0x6F,
    0x14: 0xF8,
    0x15: 0x59,
    0x16: 0x34,
    0x17: 0x85,
    0x18: 0x6C,
    0x19: 0x46,
    0x1A: 0xF4,
    0x20: 0xC9,
    0x21: 0x5D,
    0x81: 0x2B,
    0x82: 0xE6,
    0x83: 0x34,
    0x84: 0xC6,
    0x85: 0x09,
    0x86: 0x18,
    0x87: 0xA1,
    0x88: 0xD9,
    0x90: 0x3F,
    0x91: 0x13,
}
