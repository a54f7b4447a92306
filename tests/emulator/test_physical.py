"""A robot built differently from its configuration (emulator.physical), and the stand."""

from __future__ import annotations

import math

import pytest

from emulator import Emulator, EmulatorValueError
from emulator.physical import MISCALIBRATED, Physical, physical_from
from emulator.transport.inprocess import parse_emu_url


def _spin(emu: Emulator, wheel: int, effort: int, seconds: float) -> None:
    """Drive one motor directly (no firmware): what the plant does with a given effort."""
    from protocol.generated.hardware import MotorMode

    end = emu.now_us + round(seconds * 1e6)
    while emu.now_us < end:
        emu.plant.drive(wheel, effort, MotorMode.DRIVE)
        emu.advance(0.01)


def test_miscalibrated_plant_disagrees_with_its_configuration() -> None:
    emu = Emulator("diffdrive-tb6612", physical=MISCALIBRATED, stand=True)
    cfg = emu.profile.robot.config
    assert emu.profile.encoder_cpr == round(cfg.encoder_cpr * 1.07)
    assert emu.profile.wheel_radius_m == pytest.approx(cfg.wheel_diameter_um / 2e6 * 0.95)
    assert emu.profile.track_m == pytest.approx(emu.profile.robot.track_m * 1.04)
    # Wheel 0's encoder is mirrored against the configuration: its raw count, once the configured
    # encoder_invert is applied as the firmware does, runs backwards while the wheel rolls forward.
    before = emu.plant.encoder_counts()
    unit = emu.plant.units[0]
    angle0 = unit.angle_rad
    polarity = 1 if emu.profile.robot.config.motor_invert & 1 == 0 else -1
    _spin(emu, 0, 400 * polarity, 1.0)
    turned = (unit.angle_rad - angle0) / (2 * math.pi)
    assert turned > 1.0  # forward, more than a turn
    raw = emu.plant.encoder_counts()[0] - before[0]
    seen = -raw if cfg.encoder_invert & 1 else raw
    assert seen < 0
    assert abs(raw) == pytest.approx(turned * emu.profile.encoder_cpr, abs=2)


def test_nominal_robot_matches_its_configuration() -> None:
    emu = Emulator("diffdrive-bts7960")
    robot = emu.profile.robot
    assert emu.profile.physical.nominal
    assert emu.profile.encoder_cpr == robot.encoder_cpr
    assert emu.profile.wheel_radius_m == pytest.approx(robot.wheel_diameter_m / 2)
    assert emu.profile.track_m == pytest.approx(robot.track_m)


def test_steering_trim_and_ratio_move_the_true_straight_ahead() -> None:
    emu = Emulator("picar", physical=Physical(steering_trim_deg=3.0, steering_ratio=0.9))
    servo = emu.plant.servo
    assert servo is not None
    servo.angle_deg = 93.0
    assert servo.wheel_angle_rad == pytest.approx(0.0)
    servo.angle_deg = 108.0
    assert servo.wheel_angle_rad == pytest.approx(math.radians(15 * 0.9))


def test_stand_holds_the_body_while_the_wheels_spin() -> None:
    emu = Emulator("diffdrive-tb6612", stand=True)
    _spin(emu, 1, 600, 1.0)
    truth = emu.truth.plant
    assert truth.on_stand
    assert (truth.x_m, truth.y_m, truth.theta_rad) == (0.0, 0.0, 0.0)
    assert abs(truth.wheels[1].rim_speed_mm_s) > 100
    emu.set_stand(False)
    _spin(emu, 1, 600, 1.0)
    assert emu.truth.plant.distance_m > 0.05
    assert "stand" in emu.truth.fault_kinds()


def test_url_parameters() -> None:
    opts = parse_emu_url("emu://picar?physical=miscalibrated&cpr_scale=1.1&stand=1")
    assert opts.stand
    assert opts.physical.cpr_scale == 1.1
    assert opts.physical.wheel_scale == MISCALIBRATED.wheel_scale
    assert parse_emu_url("emu://").physical.nominal
    with pytest.raises(EmulatorValueError, match="physical"):
        parse_emu_url("emu://?physical=bent")
    with pytest.raises(EmulatorValueError, match="cpr_scale"):
        parse_emu_url("emu://?cpr_scale=3")
    with pytest.raises(EmulatorValueError, match="encoder_flip"):
        parse_emu_url("emu://?encoder_flip=x")
    with pytest.raises(EmulatorValueError, match="stand"):
        parse_emu_url("emu://?stand=maybe")
    assert physical_from(None, {}).describe() == "as configured"
    assert "encoder_flip=1" in MISCALIBRATED.describe()
