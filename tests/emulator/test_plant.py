"""Plant sanity: motor statics and dynamics, encoders, steering, ESC, slip. Driven directly, no firmware."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from emulator.plant.esc import Esc, EscParams, EscState
from emulator.plant.plant import Plant
from emulator.plant.servo import ServoParams, SteeringServo
from emulator.profiles import PROFILE_NAMES, get_profile
from protocol.generated.hardware import MotorMode

DT = 0.001


def _plant(name: str, mu: float = math.inf) -> Plant:
    plant = Plant(get_profile(name), DT)
    plant.vehicle.mu = mu
    plant.esc = None  # drive the motor directly: these tests are about the motor, not the ESC
    return plant


def _drive(plant: Plant, duty: float, mode: MotorMode = MotorMode.DRIVE) -> None:
    """Same robot-forward duty on every wheel (undoing the mirrored mounting, as motor_invert does)."""
    for w, unit in enumerate(plant.units):
        unit.motor.command(duty * plant.profile.motor_polarity(w), mode)


def _run(plant: Plant, seconds: float) -> list[float]:
    """Body speed (mm/s) after each step."""
    speeds = []
    start = len(speeds)
    for k in range(round(seconds / DT)):
        plant.step((start + k) * 1000)
        speeds.append(plant.vehicle.v_m_s * 1000)
    return speeds


@pytest.mark.parametrize("name", PROFILE_NAMES)
def test_steady_state_speed_is_affine_in_duty_above_the_deadband(name: str) -> None:
    profile = get_profile(name)
    duties = [0.3, 0.45, 0.6, 0.75, 0.9]
    speeds = []
    for duty in duties:
        plant = _plant(name)
        _drive(plant, duty)
        speeds.append(_run(plant, 2.0)[-1])
    # A straight line through the points: speed = slope * (duty - duty0).
    n = len(duties)
    mx, my = sum(duties) / n, sum(speeds) / n
    slope = sum((x - mx) * (y - my) for x, y in zip(duties, speeds, strict=True)) / sum((x - mx) ** 2 for x in duties)
    duty0 = mx - my / slope
    for x, y in zip(duties, speeds, strict=True):
        assert y == pytest.approx(slope * (x - duty0), rel=0.002)
    # ...which matches the analytic model and the firmware's feed-forward: full effort ~ 1000/kf mm/s.
    assert speeds[-1] == pytest.approx(profile.free_speed_mm_s(0.9), rel=0.002)
    full = slope * (1.0 - duty0)
    assert full == pytest.approx(1000 / profile.robot.pid.kf, rel=0.15)
    # Below the start-up threshold (driver deadband + dry friction) the robot does not move.
    assert 0.02 < duty0 < 0.12
    plant = _plant(name)
    _drive(plant, duty0 * 0.9)
    assert _run(plant, 1.0)[-1] == 0.0


@pytest.mark.parametrize("name", PROFILE_NAMES)
def test_speed_step_response_time_constant(name: str) -> None:
    profile = get_profile(name)
    plant = _plant(name)
    _drive(plant, 0.3)
    v0 = _run(plant, 1.5)[-1]
    _drive(plant, 0.5)
    trace = _run(plant, 1.5)
    v1 = trace[-1]
    target = v0 + (1 - math.exp(-1)) * (v1 - v0)
    t63 = next(k for k, v in enumerate(trace) if v >= target) * DT + DT
    # The winding's L/R adds a little lag on top of the mechanical time constant.
    expected = profile.time_constant_s() + profile.plant.motor.electrical_time_constant_s
    assert t63 == pytest.approx(expected, rel=0.2)
    assert 0.03 < profile.time_constant_s() < 0.1


def test_brake_stops_faster_than_coast() -> None:
    stops = {}
    for mode in (MotorMode.BRAKE, MotorMode.COAST):
        plant = _plant("diffdrive-tb6612")
        _drive(plant, 0.8)
        _run(plant, 1.0)
        _drive(plant, 0.0, mode)
        trace = _run(plant, 3.0)
        stops[mode] = next(k for k, v in enumerate(trace) if v == 0.0) * DT
    assert stops[MotorMode.BRAKE] < stops[MotorMode.COAST] / 2


@settings(max_examples=25, deadline=None)
@given(
    name=st.sampled_from(["diffdrive-tb6612", "diffdrive-bts7960"]),
    duties=st.lists(st.floats(-1.0, 1.0), min_size=1, max_size=6),
    phase=st.floats(0.0, 0.999),
)
def test_encoder_counts_floor_of_revolutions_with_direction(name: str, duties: list[float], phase: float) -> None:
    profile = get_profile(name)
    plant = _plant(name)
    for unit in plant.units:
        assert unit.encoder is not None
        unit.encoder.phase = phase
        unit.encoder._base = math.floor(phase)
    cpr = profile.robot.encoder_cpr
    for duty in duties:
        _drive(plant, duty)
        for k in range(80):
            plant.step(k * 1000)
            for w, unit in enumerate(plant.units):
                revs = unit.angle_rad / (2 * math.pi)
                own = profile.encoder_polarity(w) * revs  # a mirrored encoder counts the other way
                assert plant.encoder_counts()[w] == math.floor(own * cpr + phase) - math.floor(phase)


def test_mirrored_wheel_counts_down_when_rolling_forward() -> None:
    # diffdrive-tb6612 has encoder_invert = motor_invert = 2: the right wheel is mounted mirrored.
    plant = _plant("diffdrive-tb6612")
    _drive(plant, 0.5)
    _run(plant, 0.5)
    left, right = plant.encoder_counts()
    assert left > 0 and right < 0 and abs(left + right) <= 2
    assert plant.vehicle.v_m_s > 0


def test_disconnected_encoder_freezes_while_the_wheel_turns() -> None:
    plant = _plant("diffdrive-tb6612")
    _drive(plant, 0.5)
    _run(plant, 0.3)
    unit = plant.units[0]
    assert unit.encoder is not None
    unit.encoder.connected = False
    frozen = plant.encoder_counts()[0]
    angle = unit.angle_rad
    _run(plant, 0.3)
    assert plant.encoder_counts()[0] == frozen and unit.angle_rad > angle + 1.0
    unit.encoder.reconnect(unit.angle_rad)
    _run(plant, 0.1)
    assert plant.encoder_counts()[0] > frozen  # counting again, from where it stopped


def test_stalled_wheel_draws_stall_current() -> None:
    profile = get_profile("diffdrive-tb6612")
    plant = _plant("diffdrive-tb6612")
    plant.units[0].stalled = True
    _drive(plant, 1.0)
    _run(plant, 0.5)
    motor = profile.plant.motor
    stall = min(motor.current_limit_a, motor.supply_v * (1 - 0) / motor.resistance_ohm)
    assert plant.units[0].omega_rad_s == 0.0
    assert abs(plant.units[0].motor.current_a) == pytest.approx(stall, rel=0.01)
    # The free right wheel still drives: the robot pivots about the jammed left one, turning left.
    assert plant.vehicle.theta_rad > 0.1
    assert plant.units[0].slipping is False  # the jammed tyre grips: it is the pivot


def test_wheels_slip_under_hard_acceleration_on_a_slippery_floor() -> None:
    grip = _plant("diffdrive-bts7960", mu=0.8)
    ice = _plant("diffdrive-bts7960", mu=0.1)
    for plant in (grip, ice):
        _drive(plant, 1.0)
        _run(plant, 0.3)
    rim = [ice.units[0].angle_rad * get_profile("diffdrive-bts7960").wheel_radius_m, grip.vehicle.distance_m]
    assert any(u.slipping for u in ice.units)
    # On ice the wheels have turned further than the robot has travelled; odometry would overshoot.
    assert rim[0] > ice.vehicle.distance_m * 1.5
    assert ice.vehicle.distance_m < grip.vehicle.distance_m
    # Acceleration on ice is traction-limited: about mu * g * (load share on the driven wheels).
    body = get_profile("diffdrive-bts7960").plant.body
    assert ice.vehicle.v_m_s / 0.3 == pytest.approx(0.1 * 9.81 * body.drive_load_fraction, rel=0.15)


@pytest.mark.parametrize("steer_deg", [-25.0, -15.0, 15.0, 30.0])
def test_ackermann_turning_radius_is_wheelbase_over_tan_steer(steer_deg: float) -> None:
    profile = get_profile("picar")
    plant = _plant("picar")
    servo = plant.servo
    assert servo is not None
    pulse = round(500 + (90 + steer_deg) * 2000 / 180)
    servo.set_pulse(pulse)
    _drive(plant, 0.3)
    _run(plant, 1.0)
    theta0, dist0 = plant.vehicle.theta_rad, plant.vehicle.distance_m
    _run(plant, 2.0)
    radius = (plant.vehicle.distance_m - dist0) / abs(plant.vehicle.theta_rad - theta0)
    expected = profile.robot.wheelbase_m / math.tan(math.radians(abs(steer_deg)))
    assert radius == pytest.approx(expected, rel=0.03)
    assert math.copysign(1, plant.vehicle.theta_rad - theta0) == math.copysign(1, steer_deg)  # positive = left


def test_servo_slew_quantisation_and_travel_limits() -> None:
    servo = SteeringServo(ServoParams(travel_min_deg=60, travel_max_deg=130, resolution_deg=0.5, slew_deg_s=400))
    servo.set_pulse(500 + 120 * 2000 // 180)  # 120 deg
    steps = 0
    while servo.angle_deg < servo.target_deg:
        servo.step(DT)
        steps += 1
    assert steps * DT == pytest.approx(30 / 400, abs=2 * DT)
    servo.set_pulse(2500)  # 180 deg: beyond the linkage's travel
    assert servo.target_deg == 130
    servo.set_pulse(1501)  # 90.09 deg: below the servo's resolution
    assert servo.target_deg == 90.0


def test_esc_needs_steady_neutral_to_arm_and_learns_it() -> None:
    esc = Esc(EscParams(calibration_ms=2000))
    t = 0
    esc.set_pulse(1510)
    for _ in range(1000):
        t += 1000
        esc.step(t)
    assert esc.state is EscState.CALIBRATING
    esc.set_pulse(1700)  # throttle open during calibration: it starts over and will not drive
    t += 1000
    assert esc.step(t) == 0.0
    esc.set_pulse(1510)
    for _ in range(1999):
        t += 1000
        esc.step(t)
    assert esc.state is EscState.CALIBRATING
    for _ in range(2):
        t += 1000
        esc.step(t)
    assert esc.state is EscState.READY and esc.learned_neutral_us == 1510
    esc.set_pulse(1530)
    assert esc.step(t) == 0.0  # inside the neutral band
    esc.set_pulse(2000)
    assert esc.step(t) == 1.0
    esc.set_pulse(0)  # pulses stop (MCU reset): after the timeout the ESC needs calibrating again
    esc.step(t + 200_000)
    assert esc.state is EscState.NO_SIGNAL
