"""`roverlink robot urdf`: a URDF robot_state_publisher accepts, read back with a real URDF parser
(urdf_parser_py, what ROS's Python tools read URDFs with): one root, the node's joint names, the
wheels and sensors where the robot file puts them."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from urdf_parser_py.urdf import URDF

from host_sdk import Ackermann, RobotDescription
from protocol.robotfile import REFERENCES, reference_path
from roverlink.cli import main
from roverlink.ros2 import convert
from roverlink.ros2.frames import FrameNames, static_frames
from roverlink.ros2.params import BridgeParams
from roverlink.ros2.urdf import build_urdf, link_name

LIDAR = """
[sensors.lidar]
model = "rplidar-a1"
x_m = -0.05
y_m = 0.02
z_m = 0.3
yaw_deg = 90.0
"""


def user_file(tmp_path: Path) -> Path:
    """diffdrive-tb6612 with a wider track, bigger wheels and a lidar of its own, off centre and turned."""
    text = reference_path("diffdrive-tb6612").read_text(encoding="utf-8")
    for old, new in (("track_m = 0.2 ", "track_m = 0.27 "), ("wheel_diameter_m = 0.064", "wheel_diameter_m = 0.09")):
        assert text.count(old) == 1
        text = text.replace(old, new)
    path = tmp_path / "mine.toml"
    path.write_text(text.replace("[sensors.imu]", LIDAR.lstrip() + "\n[sensors.imu]"), encoding="utf-8")
    return path


def node_joint_names(robot: RobotDescription) -> tuple[str, ...]:
    """What the node's joint_states carries, the way the node makes it (node._on_connected)."""
    p = BridgeParams.defaults()
    kin = robot.kinematics()
    return convert.JointTracker(kin, p.wheel_joints or convert.default_wheel_joints(kin), p.steering_joint).names


def robots(tmp_path: Path) -> list[RobotDescription]:
    return [RobotDescription.load(reference_path(name)) for name in REFERENCES] + [
        RobotDescription.load(user_file(tmp_path))
    ]


def origin(urdf: URDF, joint: str) -> tuple[list[float], list[float]]:
    o = urdf.joint_map[joint].origin
    return list(o.xyz), list(o.rpy)


def test_each_robot_parses_to_one_tree_with_the_nodes_joints_and_its_mounts(tmp_path: Path) -> None:
    for robot in robots(tmp_path):
        text = build_urdf(robot)
        assert text == build_urdf(robot)  # deterministic
        urdf = URDF.from_xml_string(text)
        assert urdf.get_root() == "base_link", robot.name
        children = {j.child for j in urdf.joints}
        assert [link.name for link in urdf.links if link.name not in children] == ["base_link"]
        movable = tuple(j.name for j in urdf.joints if j.type != "fixed")
        assert movable == node_joint_names(robot), robot.name
        assert origin(urdf, "base_footprint_joint") == ([0, 0, 0], [0, 0, 0])
        frame = {"lidar": "laser", "imu": "imu_link", "camera": "camera_link"}
        mounts = robot.mounts()
        assert mounts, robot.name
        for m in mounts:
            joint = next(j for j in urdf.joints if j.child == frame[m.name])
            assert joint.parent == "base_link" and joint.type == "fixed"
            xyz, rpy = origin(urdf, joint.name)
            assert xyz == pytest.approx([m.x_m, m.y_m, m.z_m]) and rpy == pytest.approx([0, 0, math.radians(m.yaw_deg)])
        expected = {frame[m.name] for m in mounts} | ({"camera_optical_frame"} if robot.camera else set())
        assert {j.child for j in urdf.joints if j.type == "fixed"} - {"base_footprint"} == expected


def test_the_wheels_sit_at_the_track_and_the_wheel_radius(tmp_path: Path) -> None:
    for robot in robots(tmp_path):
        urdf = URDF.from_xml_string(build_urdf(robot))
        r, half = robot.wheel_diameter_m / 2, robot.track_m / 2
        names = node_joint_names(robot)
        if isinstance(robot.kinematics(), Ackermann):
            assert origin(urdf, names[0])[0] == pytest.approx([0, 0, r])
            assert origin(urdf, names[1])[0] == pytest.approx([robot.geometry.wheelbase_m, 0, r])
            steer = urdf.joint_map[names[1]]
            assert steer.type == "revolute" and list(steer.axis) == [0, 0, 1]
            s = robot.steering
            assert s is not None
            assert (steer.limit.lower, steer.limit.upper) == pytest.approx(
                (math.radians(s.min_deg - s.center_deg), math.radians(s.max_deg - s.center_deg))
            )
            wheel_ys = [v.origin.xyz[1] for v in urdf.link_map[link_name(names[0])].visuals]
            assert wheel_ys == pytest.approx([half, -half])
        else:
            assert origin(urdf, names[0])[0] == pytest.approx([0, half, r])  # left (REP-103: +y)
            assert origin(urdf, names[1])[0] == pytest.approx([0, -half, r])
        for name in names:
            joint = urdf.joint_map[name]
            for visual in urdf.link_map[joint.child].visuals:
                assert visual.geometry.radius == pytest.approx(r)
            if joint.type == "continuous":
                assert list(joint.axis) == [0, 1, 0]


def test_the_user_files_geometry_and_lidar_are_its_own(tmp_path: Path) -> None:
    robot = RobotDescription.load(user_file(tmp_path))
    urdf = URDF.from_xml_string(build_urdf(robot))
    assert origin(urdf, "left_wheel_joint")[0] == pytest.approx([0, 0.135, 0.045])
    assert origin(urdf, "laser_joint") == (pytest.approx([-0.05, 0.02, 0.3]), pytest.approx([0, 0, math.pi / 2]))


def test_body_from_the_footprint_and_no_sensor_links_without_sensors(tmp_path: Path) -> None:
    text = reference_path("diffdrive-bts7960").read_text(encoding="utf-8")
    text = text[: text.index("[sensors.lidar]")] + text[text.index("[footprint]") :]
    polygon = "[footprint]\npolygon_m = [[-0.1, -0.1], [0.3, -0.1], [0.3, 0.15], [-0.1, 0.1]]\n"
    body = text.index("[footprint]"), text.index("[calibration]")
    path = tmp_path / "bare.toml"
    path.write_text(text[: body[0]] + polygon + "\n" + text[body[1] :], encoding="utf-8")
    robot = RobotDescription.load(path)
    assert robot.mounts() == ()
    urdf = URDF.from_xml_string(build_urdf(robot))
    assert {link.name for link in urdf.links} == {"base_link", "base_footprint", "left_wheel", "right_wheel"}
    base = urdf.link_map["base_link"]
    for shape in (base.visual, base.collision):  # the polygon's bounding box
        assert list(shape.geometry.size)[:2] == pytest.approx([0.4, 0.25])
        assert list(shape.origin.xyz)[:2] == pytest.approx([0.1, 0.025])
    disc = URDF.from_xml_string(build_urdf(RobotDescription.load(reference_path("picar")))).link_map["base_link"]
    assert (disc.collision.geometry.radius, disc.collision.origin.xyz[0]) == pytest.approx((0.19, 0.13))


def test_frame_and_joint_names_are_parameters(tmp_path: Path) -> None:
    robot = RobotDescription.load(user_file(tmp_path))
    names = FrameNames(base="chassis", lidar="lidar_top", imu="imu", wheel_joints=("l", "r"))
    urdf = URDF.from_xml_string(build_urdf(robot, names))
    assert urdf.get_root() == "chassis"
    assert [j.name for j in urdf.joints if j.type == "continuous"] == ["l", "r"]
    assert {j.child for j in urdf.joints if j.type == "fixed"} >= {"lidar_top", "imu"}
    assert [f.child for f in static_frames(robot, names)][:3] == ["base_footprint", "lidar_top", "imu"]


def test_the_command_writes_it(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path, out = user_file(tmp_path), tmp_path / "mine.urdf"
    assert main(["robot", "urdf", str(path), "-o", str(out)]) == 0
    assert str(out) in capsys.readouterr().out
    assert out.read_text(encoding="utf-8") == build_urdf(RobotDescription.load(path))
    assert main(["robot", "urdf", "picar"]) == 0  # a reference robot by name, to stdout
    assert URDF.from_xml_string(capsys.readouterr().out).name == "picar"


def test_the_commands_errors_name_the_fix(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    missing = tmp_path / "nope.toml"
    assert main(["robot", "urdf", str(missing)]) == 2
    err = capsys.readouterr().err
    assert "no such file" in err and f"roverlink robot new {missing} --from" in err and "picar" in err
    bad = tmp_path / "bad.toml"
    bad.write_text(user_file(tmp_path).read_text(encoding="utf-8").replace("track_m = 0.27", "track_m = -1"))
    assert main(["robot", "urdf", str(bad), "-o", str(tmp_path / "bad.urdf")]) == 2
    err = capsys.readouterr().err
    assert "track_m" in err and f"roverlink robot check {bad}" in err
    assert not (tmp_path / "bad.urdf").exists()
