"""The parameter rules of the bridge that say what a parameter does, without ROS: an allowed
mismatch in /diagnostics, unknown and ros_arduino_bridge names, a sensor's baud, a profile's
sensors without a port, a base frame named as the footprint (tests/roverlink/ros2/
test_bridge_param_warnings.py runs the same on a node)."""

from __future__ import annotations

import dataclasses

from test_bridge_parts import snap

from host_sdk import RobotDescription
from protocol.generated.enums import FailsafeReason
from protocol.robotfile import reference_path
from roverlink.ros2.diagnostics import ERROR, WARN, DiagnosticsBuilder
from roverlink.ros2.frames import FrameNames, static_frames
from roverlink.ros2.params import (
    BY_NAME,
    OLD_NAMES,
    BridgeParams,
    link_warnings,
    profile_sensor_warnings,
    sensor_baud,
    unknown_parameter_warnings,
)


def test_an_allowed_mismatch_warns_naming_each_difference_and_a_failsafe_still_wins() -> None:
    d = DiagnosticsBuilder("roverlink")
    diffs = ("mine.toml: geometry.wheel_diameter_m = 0.07 m but the board on emu:// has wheel_diameter_um = 64000",)
    _, robot = d.build(snap(1.0, state="disarmed", mismatches=diffs))
    assert robot.level == WARN and diffs[0] in robot.message and dict(robot.values)["mismatch 1"] == diffs[0]
    _, robot = d.build(snap(2.0, state="failsafe", failsafe=FailsafeReason.COMM_TIMEOUT, mismatches=diffs))
    assert robot.level == ERROR


def test_unknown_and_ros_arduino_bridge_parameters_name_what_to_use() -> None:
    lines = unknown_parameter_warnings(["Kp", "motors_reversed", "odom_rat", "qos_overrides./odom.depth", "url"])
    assert lines == [
        "parameter Kp is ros_arduino_bridge's and is ignored: RoverLink's is the robot file's [pid] kp (robot_file)",
        "parameter motors_reversed is ros_arduino_bridge's and is ignored: RoverLink's is the robot file's "
        "[drive] motor_invert (robot_file)",
        "unknown parameter odom_rat is ignored: did you mean odom_rate or odom_frame?",
    ]
    assert not set(OLD_NAMES) & set(BY_NAME)  # an old name the node has is no old name


def test_a_sensors_baud_is_the_parameter_else_the_robot_files_else_the_datasheets() -> None:
    imu = RobotDescription.load(reference_path("diffdrive-tb6612")).imu
    assert imu is not None and imu.baud == 0
    slow = dataclasses.replace(imu, baud=9600)
    assert (sensor_baud(0, None), sensor_baud(0, imu), sensor_baud(0, slow), sensor_baud(230400, slow)) == (
        None,
        None,
        9600,
        230400,
    )


def test_a_profile_with_sensors_and_no_urls_warns_on_a_real_port_only() -> None:
    picar = BridgeParams.defaults(profile="picar", url="/dev/ttyACM0")
    (line,) = profile_sensor_warnings(picar)
    assert "lidar_url parameter is empty: no scan and no laser frame" in line
    assert profile_sensor_warnings(dataclasses.replace(picar, lidar_url="/dev/ttyUSB0")) == []
    assert profile_sensor_warnings(dataclasses.replace(picar, url="emu://picar")) == []
    (line,) = profile_sensor_warnings(BridgeParams.defaults(profile="diffdrive-tb6612"))
    assert "imu_url parameter is empty: no imu and no imu_link frame" in line


def test_a_base_frame_named_as_the_footprint_has_no_transform_to_itself() -> None:
    frames = static_frames("diffdrive-tb6612", FrameNames(base="base_footprint"), ["imu"])
    assert [(f.parent, f.child) for f in frames] == [("base_footprint", "imu_link")]


def test_a_board_baud_carried_over_from_ros_arduino_bridge_and_an_unused_camera_warn() -> None:
    board = BridgeParams.defaults(url="/dev/ttyACM0")
    assert link_warnings(board) == []
    (line,) = link_warnings(dataclasses.replace(board, baud=57600))
    assert line.startswith("baud 57600: the RoverLink firmware opens its port at 115200 ") and "57600" in line
    assert link_warnings(dataclasses.replace(board, baud=57600, url="emu://picar")) == []  # the emulator takes any
    (line,) = link_warnings(BridgeParams.defaults(url="emu://picar?lidar=ydlidar-f4&camera=320x240"))
    assert "camera= is not used" in line
    assert link_warnings(BridgeParams.defaults(url="emu://picar?lidar=ydlidar-f4")) == []
