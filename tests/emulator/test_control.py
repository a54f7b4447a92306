"""The control law and config rules of docs/control.md, unit by unit."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from emulator.firmware.config import (
    IMAGE_SIZE,
    Gains,
    LoadResult,
    decode_image,
    encode_image,
    first_inconsistent,
    first_out_of_range,
)
from emulator.firmware.control import WheelPid, ramp_step, round_half_away
from emulator.firmware.core import Firmware
from emulator.profiles import get_profile
from host_sdk import messages
from host_sdk.framing import encode_frame
from host_sdk.messages import SetConfig, SetPid
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH
from protocol.generated.profiles import PROFILES

GAINS = Gains(kp=1.0, ki=6.0, kd=0.0, kf=1.5)


def test_round_half_away_from_zero() -> None:
    assert [round_half_away(x) for x in (0.5, 1.5, 2.5, -0.5, -1.5, 0.49, -0.49)] == [1, 2, 3, -1, -2, 0, 0]


@given(
    ramped=st.floats(-2000, 2000),
    target=st.floats(-2000, 2000),
    accel=st.floats(0.01, 100),
    decel=st.floats(0.01, 100),
)
def test_ramp_moves_toward_target_within_the_right_limit(
    ramped: float, target: float, accel: float, decel: float
) -> None:
    nxt = ramp_step(ramped, target, accel, decel)
    speeding_up = (ramped == 0 or (ramped > 0) == (target > 0)) and abs(target) > abs(ramped)
    limit = accel if speeding_up else decel
    assert abs(nxt - ramped) <= limit + 1e-9
    assert abs(target - nxt) <= abs(target - ramped) + 1e-9  # never away from the target
    if abs(target - ramped) <= limit:
        assert nxt == target


def test_reversal_goes_through_zero_at_the_decel_limit() -> None:
    r, trace = 100.0, []
    for _ in range(20):
        r = ramp_step(r, -100.0, accel_step=10.0, decel_step=30.0)
        trace.append(r)
    # 100 -> 70 -> 40 -> 10 -> -20 (decel while slowing, the step through zero too) -> -30 -> ... (accel)
    assert trace[:6] == [70.0, 40.0, 10.0, -20.0, -30.0, -40.0]


def test_pid_is_quiet_at_standstill_and_clears_its_integrator() -> None:
    pid = WheelPid()
    pid.update(100, 100, 50, gains=GAINS, max_effort=1000, dt=0.01)
    assert pid.integral != 0
    u, sat = pid.update(0, 0, 20, gains=GAINS, max_effort=1000, dt=0.01)
    assert (u, sat, pid.integral) == (0, False, 0.0)


def test_pid_terms_and_integral_timing() -> None:
    pid = WheelPid()
    g = Gains(kp=2.0, ki=10.0, kd=0.5, kf=1.0)
    u, _ = pid.update(100, 100, 80, gains=g, max_effort=1000, dt=0.01)
    # kf*r + kp*e + integral(before this tick: 0) - kd*(m - m_prev)/dt = 100 + 40 + 0 - 0.5*80/0.01
    assert pid.u_unsat == pytest.approx(100 + 40 - 4000)
    assert u == -1000  # clamped
    # e = +20 drives u_unsat back up toward the range: integrate despite the saturation
    assert pid.integral == pytest.approx(10.0 * 20 * 0.01)


def test_anti_windup_stops_integrating_into_the_limit() -> None:
    pid = WheelPid()
    for _ in range(500):
        u, sat = pid.update(600, 600, 0, gains=GAINS, max_effort=1000, dt=0.01)  # wheel stuck
    assert sat and u == 1000
    # Integration stopped once the output saturated: the integrator stays far below its clamp.
    assert pid.integral < 200
    # The moment the wheel frees itself the output leaves saturation at once (no wound-up integral).
    u, sat = pid.update(600, 600, 650, gains=GAINS, max_effort=1000, dt=0.01)
    assert not sat and u < 1000


def test_static_friction_is_fed_forward_with_the_setpoints_sign() -> None:
    """The same cases as the C++ core's test (test_core.cpp, "pid: static friction")."""
    pid = WheelPid()
    g = Gains(kp=0.0, ki=0.0, kd=0.0, kf=1.0, ks=80.0)
    assert pid.update(10, 10, 0, gains=g, max_effort=1000, dt=0.01) == (90, False)
    assert pid.update(-1, -0.01, 0, gains=g, max_effort=1000, dt=0.01) == (-80, False)  # reversing: at once
    assert pid.update(0, 0, 0, gains=g, max_effort=1000, dt=0.01) == (0, False)
    assert pid.update(950, 950, 0, gains=g, max_effort=1000, dt=0.01) == (1000, True)


def test_effort_limit_clamps_and_reports_saturation() -> None:
    pid = WheelPid()
    u, sat = pid.update(2000, 2000, 0, gains=Gains(0.3, 1.5, 0.0, 0.4), max_effort=600, dt=0.01)
    assert (u, sat) == (600, True)


def test_config_range_and_consistency_rules() -> None:
    good = get_profile("picar").robot.config
    assert first_out_of_range(good) is None and first_inconsistent(good) is None
    fields = [f.name for f in SetConfig.FIELDS]
    bad = SetConfig(**{**good.fields(), "feedback_hz": 0})
    assert first_out_of_range(bad) == fields.index("feedback_hz")
    swapped = SetConfig(**{**good.fields(), "steering_min_cdeg": 9500})
    assert first_inconsistent(swapped) == fields.index("steering_center_cdeg")
    esc = SetConfig(**{**good.fields(), "esc_neutral_us": 2000})
    assert first_inconsistent(esc) == fields.index("esc_neutral_us")
    assert first_out_of_range(SetPid(0, math.nan, 0.0, 0.0, 0.0, 0.0)) == 1
    assert first_out_of_range(SetPid(0, 1.0, 0.0, math.inf, 0.0, 0.0)) == 3
    assert first_out_of_range(SetPid(0, 1.0, 0.0, 0.0, 0.0, -1.0)) == 5


def test_eeprom_image_round_trip_and_corruption() -> None:
    robot = get_profile("diffdrive-bts7960").robot
    gains = [Gains.of(robot.pid), Gains(1.0, 2.0, 0.5, 0.25, 30.0)]
    image = encode_image(robot.config, gains)
    assert len(image) == IMAGE_SIZE == 89  # the C++ core's layout (docs/firmware.md)
    assert image[:3] == b"RL\x01"
    assert decode_image(image) == (LoadResult.OK, robot.config, gains)
    for i in range(IMAGE_SIZE):
        broken = bytearray(image)
        broken[i] ^= 0x04
        result, config, _ = decode_image(bytes(broken))
        # The header catches a flip in its 5 bytes, the CRC-16 every other single-bit error.
        assert result is (LoadResult.NO_IMAGE if i < 5 else LoadResult.BAD_CRC) and config is None
    assert decode_image(b"\xff" * IMAGE_SIZE)[0] is LoadResult.NO_IMAGE  # a blank EEPROM
    from host_sdk.messages import SetConfig as Sc
    from protocol.codec.crc import crc16

    bad = Sc(**{**robot.config.fields(), "esc_neutral_us": 2100})  # in range, inconsistent
    body = encode_image(bad, gains)[:-2]
    assert decode_image(body + crc16(body).to_bytes(2, "little"))[0] is LoadResult.INVALID


class _WrapBoard:
    """A Board whose micros() the test sets (u32, wraps), for the firmware model alone."""

    eeprom_size = 1024

    def __init__(self) -> None:
        self.t = 0
        self.esc_us = 0
        self.out = b""
        self.eeprom = bytearray(b"\xff" * self.eeprom_size)

    def micros(self) -> int:
        return self.t % (1 << 32)

    def read_encoders(self) -> list[int]:
        return [0, 0]

    def zero_encoders(self) -> None:
        pass

    def drive(self, wheel: int, effort_permille: int, mode: object) -> None:
        pass

    def esc_pulse(self, pulse_us: int) -> None:
        self.esc_us = pulse_us

    def steering_pulse(self, pulse_us: int) -> None:
        pass

    def lights(self, mask: int) -> None:
        pass

    def eeprom_read(self, address: int, length: int) -> bytes:
        return bytes(self.eeprom[address : address + length])

    def eeprom_write(self, address: int, data: bytes) -> bool:
        self.eeprom[address : address + len(data)] = data
        return True

    def entropy(self) -> int:
        return 12345

    def serial_write(self, data: bytes) -> None:
        self.out += data


def test_esc_arming_window_does_not_come_back_when_micros_wraps() -> None:
    # control.md 5: neutral only "for esc_arm_ms after boot". The model compared micros() modulo
    # 2^32 with the window on every tick, so 71.6 minutes after boot it held the drive at neutral
    # for another esc_arm_ms; the C++ core latches the end of the window.
    robot = PROFILES["picar"]
    board = _WrapBoard()
    fw = Firmware(board, robot)
    fw.setup()
    neutral = robot.config.esc_neutral_us
    board.t = (robot.config.esc_arm_ms + 10) * 1000
    fw.tick()  # the window is over
    board.t = (1 << 32) + 100_000  # micros() has wrapped: 100 ms "after boot" again
    fw.on_bytes(encode_frame(messages.Hello(PROTOCOL_VERSION, SPEC_HASH, 0, 0, 0), 0))
    fw.on_bytes(encode_frame(messages.Arm(fw.boot_id), 1))
    fw.on_bytes(encode_frame(messages.SetAckermann(300, 0), 2))
    board.t += 10_000
    fw.tick()
    assert fw.efforts[0] > 0 and board.esc_us > neutral
