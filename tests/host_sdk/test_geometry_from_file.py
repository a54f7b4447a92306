"""host_sdk.geometry from a robot file: the footprint, camera and lidar mount are the file's."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from host_sdk import Robot, RobotDescription
from host_sdk.geometry import RobotGeometry, geometry, robot_geometry, sensor_mounts
from host_sdk.profiles import kinematics_for
from protocol.robotfile import reference_path

CAMERA = '[sensors.camera]\nmodel = "pi-camera-v2"'


def _own_picar(tmp_path: Path) -> Path:
    """The PiCar's file with the camera moved and turned, another lens size and a bigger body."""
    text = reference_path("picar").read_text()
    head, camera = text.split(CAMERA)
    camera = camera.replace("x_m = 0.3 ", "x_m = 0.21 ", 1).replace("y_m = 0.0 ", "y_m = 0.04 ", 1)
    camera = camera.replace("yaw_deg = 0.0 ", "yaw_deg = 10.0 ", 1)
    camera = camera.replace("radius_m = 0.19 ", "radius_m = 0.27 ", 1)
    extra = "\nwidth = 640\nheight = 480\nhfov_deg = 70.0"
    path = tmp_path / "mine.toml"
    path.write_text(head + CAMERA + extra + camera)
    return path


def test_a_file_with_another_camera_and_body_gives_those_numbers(tmp_path: Path) -> None:
    desc = RobotDescription.load(_own_picar(tmp_path))
    geo = RobotGeometry.from_description(desc)
    assert geo.footprint.radius_m == pytest.approx(0.27)
    cam = geo.camera
    assert (cam.width, cam.height) == (640, 480)
    assert (cam.mount_x_m, cam.mount_y_m) == pytest.approx((0.21, 0.04))
    assert cam.mount_yaw_rad == pytest.approx(math.radians(10.0))
    assert cam.fx == pytest.approx((640 / 2) / math.tan(math.radians(35.0)), rel=1e-3)
    reference = geometry("picar", kinematics_for("picar"), config=desc.config())
    assert geo.lidar_mount == reference.lidar_mount  # unchanged in the file
    assert geo.min_turn_radius_m == reference.min_turn_radius_m > 0
    assert geo.curvatures == reference.curvatures and geo.curvatures


def test_a_robot_on_the_files_emulator_gets_the_files_geometry_and_mounts(tmp_path: Path) -> None:
    path = _own_picar(tmp_path)
    desc = RobotDescription.load(path)
    with Robot.connect(f"emu://?robot={path}&clock=virtual") as robot:
        assert robot.description is None  # no robot= given: the emulator's file is used
        assert robot_geometry(robot) == RobotGeometry.from_description(desc, robot.kinematics, config=robot.config)
        mounts = sensor_mounts(robot, ["camera", "lidar"])
    assert (mounts["camera"].x_m, mounts["camera"].y_m) == pytest.approx((0.21, 0.04))
    assert mounts["lidar"] == desc.sensors().placed("lidar")


def test_a_robot_connected_with_a_file_gets_the_files_geometry(tmp_path: Path) -> None:
    path = _own_picar(tmp_path)
    with Robot.connect("emu://picar?clock=virtual", robot=path) as robot:
        assert robot.description is not None and robot.description.path == str(path)
        geo = robot_geometry(robot)
        assert geo.footprint.radius_m == pytest.approx(0.27)
        assert robot_geometry(robot, "picar").footprint.radius_m == pytest.approx(0.19)  # a profile wins
        assert sensor_mounts(robot, ["camera"])["camera"].yaw_rad == pytest.approx(math.radians(10.0))
