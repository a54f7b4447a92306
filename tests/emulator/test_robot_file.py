"""The emulated robot a robot file describes (emulator.robot_file, `emu://?robot=PATH`)."""

from __future__ import annotations

from pathlib import Path

import pytest

from emulator import Emulator
from emulator.errors import EmulatorValueError
from emulator.profiles import PLANTS, get_profile
from emulator.robot_file import nearest_reference, profile_from_file
from emulator.sensors.rig import attach
from emulator.transport.inprocess import EmulatorTransport, parse_emu_url
from host_sdk import Robot
from host_sdk.enums import Capability
from protocol.generated.profiles import ROBOT_SENSORS
from protocol.robotfile import REFERENCES, RobotFileError, load, reference_path


def edited(tmp_path: Path, reference: str, *changes: tuple[str, str], name: str = "mine.toml") -> Path:
    """A copy of the reference robot's file with each (old, new) text replaced (each must be there)."""
    text = reference_path(reference).read_text(encoding="utf-8")
    for old, new in changes:
        assert old in text, old
        text = text.replace(old, new)
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("name", REFERENCES)
def test_a_reference_robots_file_gives_that_reference_robot(name: str) -> None:
    built, ref = profile_from_file(reference_path(name)), get_profile(name)
    assert nearest_reference(load(reference_path(name))) == name
    assert built.plant == PLANTS[name]
    assert built.sensors == ROBOT_SENSORS[name]
    same = ("board", "capabilities", "kinematics", "feedback_mode", "track_m", "wheelbase_m")
    same += ("wheel_diameter_m", "encoder_cpr", "config", "pid", "wiring")
    assert {k: getattr(built.robot, k) for k in same} == {k: getattr(ref.robot, k) for k in same}
    assert built.robot.example == name  # IDENTITY.robot_name: the file's name


def test_the_plant_and_firmware_defaults_come_from_the_file(tmp_path: Path) -> None:
    changes = [('name = "diffdrive-tb6612"', 'name = "wide-one"'), ("track_m = 0.2 ", "track_m = 0.32 ")]
    changes += [("wheel_diameter_m = 0.064", "wheel_diameter_m = 0.081"), ("kp = 1.0 ", "kp = 0.8 ")]
    changes += [
        ("counts_per_rev = 1560", "counts_per_rev = 2000"),
        ("\ninvert = [false, true]", "\ninvert = [true, false]"),
    ]
    path = edited(tmp_path, "diffdrive-tb6612", *changes)
    emu = Emulator(profile_from_file(path), seed=1)
    assert emu.profile.robot_file == str(path)
    assert [u.y_m for u in emu.plant.units] == pytest.approx([0.16, -0.16])
    assert emu.profile.wheel_radius_m == pytest.approx(0.0405)
    assert emu.profile.encoder_cpr == 2000
    assert [emu.profile.encoder_polarity(w) for w in (0, 1)] == [-1, 1]
    assert [emu.profile.motor_polarity(w) for w in (0, 1)] == [1, -1]  # motor_invert as in the reference
    assert emu.profile.robot.config.wheel_diameter_um == 81000
    assert emu.profile.robot.pid.kp == pytest.approx(0.8)
    assert emu.truth.profile == "wide-one"


def test_an_ackermann_file_sets_wheelbase_steering_and_esc(tmp_path: Path) -> None:
    path = edited(
        tmp_path,
        "picar",
        ("wheelbase_m = 0.26", "wheelbase_m = 0.34"),
        ("min_deg = 65.0", "min_deg = 50.0"),
        ("max_deg = 125.0", "max_deg = 130.0"),
        ("center_deg = 90.0", "center_deg = 92.0"),
        ("neutral_pulse_s = 0.0015", "neutral_pulse_s = 0.00152"),
    )
    emu = Emulator(profile_from_file(path), seed=1)
    assert emu.plant.vehicle.wheelbase == pytest.approx(0.34)
    servo = emu.profile.servo
    assert servo is not None
    assert (servo.travel_min_deg, servo.travel_max_deg, servo.straight_deg) == (45.0, 135.0, 92.0)
    assert emu.plant.esc is not None and emu.plant.esc.params.nominal_neutral_us == 1520
    assert emu.profile.robot.config.steering_center_cdeg == 9200


def test_the_nearest_reference_is_the_same_driver_else_the_closest_wheel(tmp_path: Path) -> None:
    big = ("wheel_diameter_m = 0.064", "wheel_diameter_m = 0.088")
    assert nearest_reference(load(edited(tmp_path, "diffdrive-tb6612", big))) == "diffdrive-tb6612"
    l298n = edited(tmp_path, "diffdrive-tb6612", big, ('driver = "TB6612"', 'driver = "L298N"'))
    text = l298n.read_text(encoding="utf-8").replace(", standby = 26 }", " }")
    l298n.write_text(text, encoding="utf-8")
    assert nearest_reference(load(l298n)) == "diffdrive-bts7960"  # no L298N reference: 90 mm wheels


def test_the_sensor_rig_uses_the_files_mounts_and_footprint(tmp_path: Path) -> None:
    path = edited(tmp_path, "picar", ("x_m = 0.18  #", "x_m = 0.05  #"), ("radius_m = 0.19", "radius_m = 0.25"))
    emu = Emulator(profile_from_file(path), seed=1)
    rig = attach(emu, world="empty", lidar="ydlidar-f4")
    mount = rig.mount_for("lidar", "ydlidar-f4")
    assert (mount.x_m, mount.z_m) == (0.05, 0.16)
    assert rig.world.body.footprint_radius_m == 0.25
    assert rig.mount_for("imu", "jy901") == ROBOT_SENSORS["picar"].placed("imu", "jy901")  # none: the default spot


def test_the_url_takes_a_robot_file_in_place_of_a_profile(tmp_path: Path) -> None:
    path = edited(tmp_path, "picar", ("wheelbase_m = 0.26", "wheelbase_m = 0.3"))
    assert parse_emu_url(f"emu://?robot={path}&seed=3").robot == str(path)
    with EmulatorTransport.from_url(f"emu://?robot={path}&clock=virtual") as transport:
        assert transport.profile is None  # not a reference robot, whatever its name
        assert transport.robot_file == str(path)
        assert transport.emulator.plant.vehicle.wheelbase == pytest.approx(0.3)
    for url in (f"emu://picar?robot={path}", "emu://?robot="):
        with pytest.raises(EmulatorValueError, match="robot"):
            parse_emu_url(url)


def test_a_missing_file_or_a_bad_key_is_the_files_error(tmp_path: Path) -> None:
    with pytest.raises(RobotFileError, match=r"missing\.toml: no such file"):
        EmulatorTransport.from_url(f"emu://?robot={tmp_path / 'missing.toml'}")
    path = edited(tmp_path, "picar", ("track_m = 0.16", "trak_m = 0.16"))
    line = next(i for i, x in enumerate(path.read_text(encoding="utf-8").splitlines(), 1) if x.startswith("trak_m"))
    with pytest.raises(RobotFileError) as caught:
        EmulatorTransport.from_url(f"emu://?robot={path}")
    assert f"{path}:{line}: geometry.trak_m: unknown key (did you mean 'track_m'?)" in str(caught.value)


def test_physical_deviations_apply_to_the_files_robot(tmp_path: Path) -> None:
    path = edited(tmp_path, "diffdrive-tb6612", ("wheel_diameter_m = 0.064", "wheel_diameter_m = 0.07"))
    with EmulatorTransport.from_url(f"emu://?robot={path}&wheel_scale=1.02") as transport:
        profile = transport.emulator.profile
    assert profile.wheel_radius_m == pytest.approx(0.035 * 1.02)  # the real robot: 2 % larger wheels
    assert profile.robot.config.wheel_diameter_um == 70000  # the firmware: the file's
    assert profile.robot_file == str(path)


def test_a_robot_without_encoders_runs_open_loop_as_the_firmware_does(tmp_path: Path) -> None:
    """No ENCODERS capability: the effort is the feed-forward alone, kf * r + ks (the C++ core's
    open loop, test_core.cpp), and the reported speeds are 0."""
    pins = "pins = [\n    { a = 2, b = 3 },\n    { a = 18, b = 19 },\n]"
    path = edited(tmp_path, "diffdrive-tb6612", (pins, "pins = []"))
    with Robot.connect(f"emu://?robot={path}&clock=virtual") as robot:
        assert not robot.identity.capabilities & Capability.ENCODERS
        gains = robot.pid(0)
        robot.arm()
        for _ in range(60):  # past the ramp (200 mm/s at 1 m/s^2: 0.2 s)
            robot.set_wheel_speeds(0.2, -0.2)
            fb = robot.wait_feedback()
        robot.stop()
    want = round(gains.kf * 200 + gains.ks) / 1000
    assert fb.efforts == pytest.approx((want, -want)) and fb.wheel_speeds_m_s == (0.0, 0.0)


def _without_emulator(text: str) -> str:
    """The file's text with every [emulator.*] section taken out (the sections before [firmware])."""
    return text[: text.index("\n[emulator.")] + "\n" + text[text.index("[firmware]") :]


def test_the_files_emulator_sections_are_the_plants_physics(tmp_path: Path) -> None:
    path = edited(
        tmp_path,
        "diffdrive-tb6612",
        ("supply_v = 6.0", "supply_v = 7.2"),
        ("mass_kg = 1.2", "mass_kg = 1.9"),
        ("gear_ratio = 30.0", "gear_ratio = 48.0"),
        ("current_limit_a = 3.2  #", "# current_limit_a = 3.2  #"),
    )
    plant = profile_from_file(path).plant
    assert (plant.motor.supply_v, plant.motor.gear_ratio, plant.body.mass_kg) == (7.2, 48.0, 1.9)
    assert plant.motor.current_limit_a == float("inf")  # absent: no limit
    assert plant.motor.resistance_ohm == PLANTS["diffdrive-tb6612"].motor.resistance_ohm


def test_a_file_without_emulator_sections_runs_on_the_nearest_references_physics(tmp_path: Path) -> None:
    """The motor comes with its gearbox: the reference's ratio, not the file's informative one."""
    text = _without_emulator(reference_path("picar").read_text(encoding="utf-8"))
    path = tmp_path / "bare.toml"
    path.write_text(text.replace("gear_ratio = 28.0", "gear_ratio = 3.0"), encoding="utf-8")
    robot = load(path)
    assert robot.emulator.motor is None and robot.emulator.body is None
    assert profile_from_file(path).plant == PLANTS["picar"]


@pytest.mark.parametrize(
    ("old", "new", "problem"),
    [
        ("supply_v = 6.0", "supply_v = 0.0", "emulator.motor.supply_v: = 0.0: out of range (allowed: 0.1..100 V)"),
        ("deadband = 0.02", "deadband = 0.9", "emulator.motor.deadband: = 0.9: out of range (allowed: 0..0.5)"),
        ("mass_kg = 1.2", 'mass_kg = "heavy"', "emulator.body.mass_kg: = 'heavy': expected a number (0.01..1000 kg)"),
        ("[emulator.body]", "[emulator.chassis]", "emulator.chassis: unknown part (valid: motor, body, esc, servo)"),
        ("mass_kg = 1.2", "mas_kg = 1.2", "emulator.body.mas_kg: unknown key (did you mean 'mass_kg'?)"),
    ],
)
def test_a_bad_emulator_value_is_refused_naming_the_file_and_key(
    tmp_path: Path, old: str, new: str, problem: str
) -> None:
    path = edited(tmp_path, "diffdrive-tb6612", (old, new))
    with pytest.raises(RobotFileError) as info:
        profile_from_file(path)
    assert f"{path}:" in str(info.value) and problem in str(info.value), str(info.value)
