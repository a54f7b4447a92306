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
from emulator.profiles import get_profile
from host_sdk.messages import SetConfig, SetPid

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
    assert first_out_of_range(SetPid(0, math.nan, 0.0, 0.0, 0.0)) == 1
    assert first_out_of_range(SetPid(0, 1.0, 0.0, math.inf, 0.0)) == 3


def test_eeprom_image_round_trip_and_corruption() -> None:
    robot = get_profile("diffdrive-bts7960").robot
    gains = [Gains.of(robot.pid), Gains(1.0, 2.0, 0.5, 0.25)]
    image = encode_image(robot.config, gains)
    assert len(image) == IMAGE_SIZE == 81  # the C++ core's layout (docs/firmware.md)
    assert image[:3] == b"RL\x01"
    assert decode_image(image) == (LoadResult.OK, robot.config, gains)
    for i in range(IMAGE_SIZE):
        broken = bytearray(image)
        broken[i] ^= 0x04
        result, config, _ = decode_image(bytes(broken))
        # The header catches a flip in its 5 bytes, the CRC-16 every other single-bit error.
        assert result is (LoadResult.NO_IMAGE if i < 5 else LoadResult.BAD_CRC) and config is None
    assert decode_image(b"\xff" * IMAGE_SIZE)[0] is LoadResult.NO_IMAGE  # a blank EEPROM
    from host_sdk.codec.crc import crc16
    from host_sdk.messages import SetConfig as Sc

    bad = Sc(**{**robot.config.fields(), "esc_neutral_us": 2100})  # in range, inconsistent
    body = encode_image(bad, gains)[:-2]
    assert decode_image(body + crc16(body).to_bytes(2, "little"))[0] is LoadResult.INVALID
