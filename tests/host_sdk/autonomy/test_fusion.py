"""The pose EKF on synthetic motion with known truth (the emulator's drives: test_fusion_emulator.py)."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from host_sdk.errors import CommandRangeError
from host_sdk.fusion import DIFF_DRIVE_PARAMS, EkfParams, OdometryIncrements, PoseEkf, compass_heading, params_for
from host_sdk.kinematics import Ackermann, DiffDrive

RATE_HZ = 200
ODO_HZ = 50


def run(
    ekf: PoseEkf,
    seconds: float,
    *,
    speed: float,
    turn_rate: float,
    bias: float = 0.0,
    wheel_turn_scale: float = 1.0,
    start_s: float = 0.0,
    rng: np.random.Generator | None = None,
    heading: list[float] | None = None,
) -> float:
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
        # This compass's error is white (no heading-dependent part): the filter is told so.
        params = EkfParams(bias_walk=math.radians(0.05), heading_sigma=0.0, heading_noise=math.radians(2))
        ekf = PoseEkf(params)
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


TRACK_M, METRES_PER_COUNT = 0.2, 1.29e-4
"""The diff-drive car's wheels: 0.13 mm per encoder count, 0.2 m apart."""


def drive_counted(
    ekf: PoseEkf,
    rates: list[float],
    rng: np.random.Generator,
    *,
    speed: float = 0.2,
    compass: Callable[[float], float] | None = None,
) -> float:
    """Feed a drive at the given turn rate per 20 ms step: wheels that are right to an encoder count
    (each wheel's travel read in whole counts), a gyro whose bias random-walks as the filter assumes
    (the JY901's 0.01 deg/s per sqrt(s)), and optionally a compass reading `compass(true heading)`
    plus white noise. Returns the true heading at the end."""
    t, truth, travel = 0.0, 0.0, 0.0
    bias = math.radians(0.1) * rng.normal()
    phase = rng.uniform(0, METRES_PER_COUNT, 2)  # where in a count each wheel starts
    last = (0.0, 0.0, 0.0)
    for rate in rates:
        for _ in range(RATE_HZ // ODO_HZ):
            t += 1 / RATE_HZ
            bias += math.radians(0.01) * math.sqrt(1 / RATE_HZ) * rng.normal()
            ekf.add_gyro(t, rate + bias + math.radians(0.05) * rng.normal())
            if compass is not None:
                ekf.add_heading(t, compass(truth) + math.radians(0.4) * rng.normal())
        truth += rate / ODO_HZ
        travel += speed / ODO_HZ
        wheels = (travel - truth * TRACK_M / 2, travel + truth * TRACK_M / 2)  # left, right
        left, right = (
            METRES_PER_COUNT * np.floor((w + f) / METRES_PER_COUNT) for w, f in zip(wheels, phase, strict=True)
        )
        counted = ((left + right) / 2, (right - left) / TRACK_M)
        ekf.add_odometry(t, counted[0] - last[0], counted[1] - last[1])
        last = (*counted, 0.0)
    return truth


def test_wheels_read_to_an_encoder_count_are_not_taken_for_slip() -> None:
    """Driving straight, the wheels' heading flickers by a count or two from step to step (each
    wheel's count changes at its own moment): that is no slip (the filter once took it for slip some
    50 times a minute), and it does not add up."""
    ekf = PoseEkf()
    truth = drive_counted(ekf, [0.0] * 250 + [0.0] * 3000, np.random.default_rng(3), speed=0.4)
    assert ekf.slips == 0
    assert abs(ekf.pose.theta_rad - truth) < 3 * ekf.pose.heading_sigma_rad


def test_good_wheels_hold_the_heading_while_the_gyro_bias_walks() -> None:
    """A minute of turning, left at 1 rad/s and right at 0.5 rad/s, never standing still: nothing
    but the wheels can tell the gyro's bias while it random-walks (by some 2 degrees of heading in
    a minute). Wheels that are right (to a count) hold the fused heading where they are; the filter
    once trusted them so little while turning that it followed the gyro's drift."""
    for seed in range(4):
        ekf = PoseEkf()
        rates = [0.0] * 250 + [1.0 if (k // 200) % 2 == 0 else -0.5 for k in range(60 * ODO_HZ)]
        truth = drive_counted(ekf, rates, np.random.default_rng(seed))
        error = abs(ekf.pose.theta_rad - truth)
        assert error < math.radians(0.5), (seed, math.degrees(error))
        assert error <= 3 * ekf.pose.heading_sigma_rad


def test_a_compass_off_by_a_heading_dependent_error_neither_pulls_nor_overclaims() -> None:
    """An uncalibrated compass is off by some degrees depending on where the robot faces (hard
    iron), the same each time it faces that way. Read at 200 Hz, that error is not noise to average
    away: gyro and wheels that are right stay right, and the sigma covers the error (the filter once
    followed the compass by 3 degrees while claiming 0.2)."""
    for seed in range(2):
        ekf = PoseEkf()
        rates = [0.0] * 250 + [0.6 if (k // 150) % 3 == 0 else 0.0 for k in range(60 * ODO_HZ)]

        def compass(heading: float, phase: float = 0.7 * seed) -> float:
            return heading + 1.0 + math.radians(4) * math.sin(heading + phase)  # offset 1 rad, learnt

        truth = drive_counted(ekf, rates, np.random.default_rng(seed), compass=compass)
        error = abs(ekf.pose.theta_rad - truth)
        assert error < math.radians(0.5), (seed, math.degrees(error))
        assert error <= 3 * ekf.pose.heading_sigma_rad


def test_gyro_samples_read_after_their_step_at_a_changing_rate_lose_no_turn() -> None:
    """The IMU read in 50 ms batches after the odometry steps they cover, while the turn rate ramps
    up: a step fused before its samples holds the last rate, and what the samples show later goes
    into the next step (the filter once dropped it: each held stretch of a ramp lost its share, 41
    mrad here). The wheels (right, but made useless to the filter) leave the heading to the gyro's integral."""
    ekf = PoseEkf(EkfParams(wheel_heading_resolution=100.0))
    ekf.add_gyro(0.0, 0.0)  # the IMU is running when the drive starts
    batch_s, t = 0.05, 0.0
    pending = [k / RATE_HZ for k in range(1, round(4.0 * RATE_HZ) + 1)]
    odometry = [k / ODO_HZ for k in range(1, round(4.0 * ODO_HZ) + 1)]
    while odometry:
        t += batch_s
        for time_s in [o for o in odometry if o <= t + 1e-9]:
            ekf.add_odometry(time_s, 0.3 / ODO_HZ, 0.25 * (time_s**2 - (time_s - 1 / ODO_HZ) ** 2))
            odometry.remove(time_s)
        for time_s in [g for g in pending if g <= t + 1e-9]:
            ekf.add_gyro(time_s, 0.5 * time_s)  # 0.5 rad/s^2
            pending.remove(time_s)
    ekf.add_odometry(4.0 + 1e-6, 0.0, 0.0)  # one more step: the last batch's samples count in it
    assert ekf.pose.theta_rad == pytest.approx(0.25 * 4.0**2, abs=1e-4)


def test_params_for_a_robot_take_its_encoders_resolution() -> None:
    """A diff drive's heading moves by a count over its track: coarse encoders read the heading
    coarsely, and the filter must not take a count's flicker for slip. Its wheels are otherwise
    trusted further than a car's (no steering servo between command and heading)."""
    coarse = DiffDrive(wheel_radius_m=0.03, track_m=0.15, counts_per_rev=40)  # 4.7 mm a count
    assert params_for(coarse).wheel_heading_resolution == pytest.approx(2 * math.pi * 0.03 / 40 / 0.15)
    assert params_for(coarse).wheel_turn_per_m == DIFF_DRIVE_PARAMS.wheel_turn_per_m
    fine = DiffDrive(wheel_radius_m=0.032, track_m=0.2, counts_per_rev=1560)  # the diff-drive car
    assert params_for(fine) == DIFF_DRIVE_PARAMS  # finer than the default, which stays
    assert DIFF_DRIVE_PARAMS.wheel_turn_per_m < EkfParams().wheel_turn_per_m
    assert params_for(None) == EkfParams()
    assert params_for(Ackermann(wheelbase_m=0.26, wheel_radius_m=0.0325, counts_per_rev=720)) == EkfParams()
    mine = EkfParams(wheel_turn_per_m=0.01)
    assert params_for(fine, mine) == mine  # a caller's own figures are kept


def test_a_compass_off_by_hard_and_soft_iron_is_learnt_while_turning() -> None:
    """Wheels that tell nothing (made useless to the filter) and a gyro whose bias walks five times
    the JY901's: only the compass can hold the heading, and it is off by a hard-iron offset (a cos
    and sin of the heading, 3 degrees each drawn per seed) and soft iron (twice the heading). Turning left and
    right, the filter learns that curve and holds the heading to under a degree, within 3 sigma
    (taken as one error that only changes as the robot turns, the compass held it to 3.7 degrees,
    with a sigma of 4)."""
    walk = math.radians(0.05)
    for seed in range(2):
        rng = np.random.default_rng(seed)
        ekf = PoseEkf(EkfParams(bias_walk=walk, wheel_heading_resolution=100.0))
        t, truth, bias = 0.0, 0.0, math.radians(0.2)
        hard = np.radians(rng.normal(0, 3, 2))
        for step in range(60 * ODO_HZ):
            rate = 0.0 if step < 2 * ODO_HZ else (0.8 if (step // 250) % 2 == 0 else -0.4)
            for _ in range(RATE_HZ // ODO_HZ):
                t += 1 / RATE_HZ
                bias += walk * math.sqrt(1 / RATE_HZ) * rng.normal()
                truth += rate / RATE_HZ
                ekf.add_gyro(t, rate + bias + math.radians(0.05) * rng.normal())
                iron = hard[0] * math.cos(truth) + hard[1] * math.sin(truth) + math.radians(1) * math.sin(2 * truth)
                ekf.add_heading(t, truth + 1.0 + iron + math.radians(0.4) * rng.normal())  # offset 1 rad: learnt
            ekf.add_odometry(t, 0.004, rate / ODO_HZ)
        error = abs(ekf.pose.theta_rad - truth)
        assert error < math.radians(1.0), (seed, math.degrees(error))
        assert error <= 3 * ekf.pose.heading_sigma_rad, (seed, math.degrees(error))
        assert ekf.pose.heading_sigma_rad < math.radians(1.5)  # the compass is worth something
