"""The pose EKF on synthetic motion with known truth, and on the emulator with slipping wheels."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from host_sdk.errors import CommandRangeError
from host_sdk.fusion import EkfParams, OdometryIncrements, PoseEkf, compass_heading

RATE_HZ = 200
ODO_HZ = 50


def run(ekf: PoseEkf, seconds: float, *, speed: float, turn_rate: float, bias: float = 0.0,
        wheel_turn_scale: float = 1.0, start_s: float = 0.0, rng: np.random.Generator | None = None,
        heading: list[float] | None = None) -> float:  # fmt: skip
    """Feed `seconds` of motion at a constant speed and turn rate; returns the end time. The gyro
    reads the true rate plus `bias` (and noise); the wheels see the turn scaled by `wheel_turn_scale`
    (a wrong track width, or slip). `heading`, if given, collects the true heading at each step."""
    t = start_s
    truth = heading[-1] if heading else 0.0
    for _ in range(round(seconds * ODO_HZ)):
        for _ in range(RATE_HZ // ODO_HZ):
            t += 1 / RATE_HZ
            noise = rng.normal(0, math.radians(0.05)) if rng is not None else 0.0
            ekf.add_gyro(t, turn_rate + bias + noise)
        truth += turn_rate / ODO_HZ
        if heading is not None:
            heading.append(truth)
        ekf.add_odometry(t, speed / ODO_HZ, wheel_turn_scale * turn_rate / ODO_HZ)
    return t


def test_a_straight_drive_with_perfect_sensors() -> None:
    ekf = PoseEkf()
    run(ekf, 5.0, speed=0.4, turn_rate=0.0)
    p = ekf.pose
    assert (p.x_m, p.y_m, p.theta_rad) == pytest.approx((2.0, 0.0, 0.0), abs=1e-9)
    assert p.covariance[0, 0] > 0 and p.covariance[1, 1] > 0  # uncertainty grows with distance


def test_a_circle_lands_where_geometry_says() -> None:
    ekf = PoseEkf()
    heading = [0.0]
    run(ekf, 2 * math.pi / 0.5, speed=0.5, turn_rate=0.5, heading=heading)  # a circle of radius 1 m
    p = ekf.pose
    assert (p.x_m, p.y_m) == pytest.approx((math.sin(heading[-1]), 1 - math.cos(heading[-1])), abs=1e-6)
    assert p.theta_rad == pytest.approx(heading[-1], abs=1e-9)


def test_gyro_bias_is_learnt_standing_still_and_used_while_turning() -> None:
    """A 0.5 deg/s bias would add 15 degrees in 30 s of turning. Ten seconds at rest teach the
    filter the bias; the turns after that come out right even though the wheels over-read them by 10 %."""
    bias = math.radians(0.5)
    ekf = PoseEkf()
    heading = [0.0]
    t = run(ekf, 10.0, speed=0.0, turn_rate=0.0, bias=bias, heading=heading)
    assert ekf.pose.gyro_bias_rad_s == pytest.approx(bias, rel=0.02)
    run(ekf, 30.0, speed=0.3, turn_rate=0.8, bias=bias, wheel_turn_scale=1.1, start_s=t, heading=heading)
    assert ekf.pose.theta_rad == pytest.approx(heading[-1], abs=math.radians(0.5))
    assert ekf.pose.heading_sigma_rad < math.radians(1.5)
    assert ekf.pose.turn_scale_error == pytest.approx(0.1, abs=0.01)  # the wheels' 10 % was learnt


def test_slipping_wheels_are_caught_and_the_gyro_trusted() -> None:
    """The wheels claim a spin the gyro does not feel (one wheel spinning on a slippery floor):
    the steps are flagged and dropped, the heading follows the gyro."""
    ekf = PoseEkf()
    t = run(ekf, 2.0, speed=0.0, turn_rate=0.0)
    slips_before = ekf.slips
    for _ in range(50):
        for _ in range(RATE_HZ // ODO_HZ):
            t += 1 / RATE_HZ
            ekf.add_gyro(t, 0.0)
        pose = ekf.add_odometry(t, 0.004, 0.02)  # 1 rad/s according to the wheels
    assert pose.slipping and ekf.slips - slips_before == 50
    assert ekf.pose.theta_rad == pytest.approx(0.0, abs=1e-3)
    assert abs(ekf.pose.gyro_bias_rad_s) < 1e-4  # the slip did not leak into the bias


def test_without_a_gyro_it_is_wheel_odometry() -> None:
    ekf = PoseEkf()
    inc = OdometryIncrements()
    inc.step(0.0, 0.0, 0.0)
    for i in range(1, 101):
        th = 0.01 * i
        x, y = math.sin(th), 1 - math.cos(th)  # a circle of radius 1 m
        ds, turn = inc.step(x, y, th)
        assert ds == pytest.approx(0.01, rel=1e-9) and turn == pytest.approx(0.01)
        ekf.add_odometry(0.02 * i, ds, turn)
    assert (ekf.pose.x_m, ekf.pose.y_m, ekf.pose.theta_rad) == pytest.approx((math.sin(1), 1 - math.cos(1), 1.0))


def test_the_compass_bounds_a_drift_the_gyro_alone_would_keep() -> None:
    """A bias that random-walks faster than stops can teach it: with the compass the heading stays
    within the compass's own noise, without it the error grows."""
    rng = np.random.default_rng(4)
    errors = {}
    for with_compass in (False, True):
        ekf = PoseEkf(EkfParams(bias_walk=math.radians(0.05)))
        t, truth, bias = 0.0, 0.0, math.radians(0.2)
        for step in range(60 * ODO_HZ):  # a minute of turning, never still
            for _ in range(RATE_HZ // ODO_HZ):
                t += 1 / RATE_HZ
                ekf.add_gyro(t, 0.5 + bias)
            bias += math.radians(0.005) / ODO_HZ  # the bias keeps creeping
            truth += 0.5 / ODO_HZ
            ekf.add_odometry(t, 0.006, 1.08 * 0.5 / ODO_HZ)  # wheels 8 % off: no help either
            if with_compass and step % 5 == 0:
                ekf.add_heading(t, truth + 1.0 + rng.normal(0, math.radians(2)))  # offset 1 rad: learnt
        errors[with_compass] = abs(math.remainder(ekf.pose.theta_rad - truth, 2 * math.pi))
    assert errors[True] < math.radians(1.5)
    assert errors[False] > 4 * errors[True]


def test_compass_heading_of_a_level_magnetometer() -> None:
    # Field along the sensor's x: facing magnetic north; along -y: turned 90 degrees left of it.
    assert compass_heading((450, 0, -540)) == pytest.approx(0.0)
    assert compass_heading((0, -450, -540)) == pytest.approx(math.pi / 2)


def test_gyro_samples_read_after_the_odometry_steps_they_cover_count_once() -> None:
    """A host reads its IMU in batches, at its own loop rate, while FEEDBACK arrives on its own: an
    odometry step is often fused before the gyro samples of its interval are in. The filter holds
    the last rate over the gap and must not count that stretch again when the next step comes
    before the samples do (it once turned 1.45 times as far as the robot did)."""
    ekf = PoseEkf()
    rate, batch_s, t = 0.8, 0.05, 0.0
    pending = [k / RATE_HZ for k in range(1, round(4.0 * RATE_HZ) + 1)]
    odometry = [k / ODO_HZ for k in range(1, round(4.0 * ODO_HZ) + 1)]
    while odometry:
        t += batch_s
        for time_s in [o for o in odometry if o <= t + 1e-9]:  # FEEDBACK arrives as it is sent...
            ekf.add_odometry(time_s, 0.3 / ODO_HZ, rate / ODO_HZ)
            odometry.remove(time_s)
        for time_s in [g for g in pending if g <= t + 1e-9]:  # ...the IMU's batch after it
            ekf.add_gyro(time_s, rate)
            pending.remove(time_s)
    assert ekf.pose.theta_rad == pytest.approx(rate * 4.0, rel=0.01)


def test_set_pose_starts_the_pose_again_and_keeps_the_learnt_bias() -> None:
    bias = math.radians(0.5)
    ekf = PoseEkf()
    t = run(ekf, 10.0, speed=0.0, turn_rate=0.0, bias=bias)
    t = run(ekf, 4.0, speed=0.3, turn_rate=0.5, bias=bias, start_s=t)
    learnt = ekf.pose.gyro_bias_rad_s
    assert ekf.pose.covariance[0, 0] > 2e-6  # grown from 1e-6 by the drive
    ekf.set_pose(1.0, -2.0, 0.3, time_s=t + 0.5)  # the pose at a later time: the gyro before it is dropped
    for k in range(1, 101):
        ekf.add_gyro(t + k / RATE_HZ, 0.5 + bias)  # still turning until then
    p = ekf.pose
    assert (p.x_m, p.y_m, p.theta_rad, p.gyro_bias_rad_s) == (1.0, -2.0, 0.3, learnt)
    assert np.all(np.abs(p.covariance) <= 1e-6)
    ekf.add_gyro(t + 0.52, 0.5 + bias)
    p = ekf.add_odometry(t + 0.52, 0.006, 0.01)
    assert p.theta_rad == pytest.approx(0.31, abs=1e-3) and not p.slipping  # only the 20 ms after it
    with pytest.raises(CommandRangeError, match="y_m"):
        ekf.set_pose(0.0, math.nan, 0.0)


def test_covariance_stays_symmetric_and_positive() -> None:
    ekf = PoseEkf()
    run(ekf, 20.0, speed=0.3, turn_rate=0.4, bias=0.01, rng=np.random.default_rng(1))
    p = ekf.P
    np.testing.assert_allclose(p, p.T, atol=1e-12)
    assert np.linalg.eigvalsh(p[:4, :4]).min() > 0


def test_bad_inputs_name_themselves() -> None:
    ekf = PoseEkf()
    with pytest.raises(CommandRangeError, match="rate_rad_s"):
        ekf.add_gyro(0.0, math.nan)
    with pytest.raises(CommandRangeError, match="distance_m"):
        ekf.add_odometry(0.0, math.inf, 0.0)
    with pytest.raises(CommandRangeError, match="heading_rad"):
        ekf.add_heading(0.0, math.nan)


def _benchmark() -> Any:
    path = Path(__file__).resolve().parents[3] / "benchmarks" / "fusion.py"
    spec = importlib.util.spec_from_file_location("fusion_benchmark", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


def test_on_the_emulator_with_slip_the_ekf_heading_is_5x_better_than_odometry() -> None:
    """A minute of the benchmark's drive (benchmarks/fusion.py runs two) on the diff-drive car with
    the tyres' friction at 0.15: the wheels slip on every turn and odometry's heading drifts."""
    end = _benchmark().drive("diffdrive-tb6612", "slippery", seed=1, seconds=60.0).readings[-1]
    assert abs(end.wheels.heading_deg) > 15  # the slip is real
    assert abs(end.wheels.heading_deg) >= 5 * abs(end.ekf.heading_deg)
    assert abs(end.ekf.heading_deg) < 4 * end.ekf.heading_sigma_deg + 0.5  # and the filter knows roughly how good it is
