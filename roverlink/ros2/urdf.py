"""A robot file as a URDF for robot_state_publisher (`roverlink robot urdf FILE`; docs/ros2.md).

Plain Python (no rclpy): the command and the node share the frames (roverlink.ros2.frames) and the
joint names (roverlink.ros2.convert, what the node's joint_states carries).

- `base_link` (the root) is the pose point on the ground; `base_footprint` is a fixed child at the
  same place (REP-120).
- The body, visual and collision alike, is the footprint as a slab BODY_HEIGHT_M thick resting on
  the axles: a disc as a cylinder, a box as a box, a polygon as its bounding box.
- The wheels hang on continuous joints named as joint_states names them: left and right at
  +-track/2 on a differential robot; on a car the driven rear axle at the pose point and a
  revolute steering joint at the front axle (wheelbase ahead, limits the servo's travel around its
  centre), each axle's link carrying both its wheels' cylinders at +-track/2.
- Each sensor the file carries is a fixed link at its mount (x, y, z, yaw); the camera also gets
  its REP-103 optical frame.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence

from host_sdk import Ackermann, DiffDrive, RobotDescription
from roverlink.ros2 import convert
from roverlink.ros2.frames import DEFAULT_NAMES, FrameNames, StaticFrame, static_frames

BODY_HEIGHT_M = 0.05
"""The body slab's thickness (a robot file has no height for it)."""
WHEEL_WIDTH_M = 0.025
"""The wheels' drawn width (a robot file has none)."""


def _num(value: float) -> str:
    text = repr(round(value, 9) + 0.0)  # + 0.0: no "-0.0"
    return text[:-2] if text.endswith(".0") else text


def _nums(*values: float) -> str:
    return " ".join(_num(v) for v in values)


def _origin(parent: ET.Element, xyz: Sequence[float], rpy: Sequence[float] = (0.0, 0.0, 0.0)) -> None:
    ET.SubElement(parent, "origin", xyz=_nums(*xyz), rpy=_nums(*rpy))


def _shape(parent: ET.Element, tag: str, xyz: Sequence[float], rpy: Sequence[float], size: dict[str, str]) -> None:
    """A visual or collision element with one geometry (`size`: its kind, and its attributes)."""
    element = ET.SubElement(parent, tag)
    _origin(element, xyz, rpy)
    attrs = dict(size)
    ET.SubElement(ET.SubElement(element, "geometry"), attrs.pop("kind"), attrs)


def link_name(joint: str) -> str:
    """The child link of a joint: its name without `_joint`, else with `_link` added."""
    return joint.removesuffix("_joint") if joint.endswith("_joint") else f"{joint}_link"


def joint_names(robot: RobotDescription, names: FrameNames = DEFAULT_NAMES) -> tuple[str, ...]:
    """The movable joints, in the node's joint_states order (wheels, then a car's steering)."""
    kin = robot.kinematics()
    # The node's own joint list (ValueError if wheel_joints has the wrong count for this robot).
    return convert.JointTracker(
        kin, names.wheel_joints or convert.default_wheel_joints(kin), names.steering_joint
    ).names


def _body(base: ET.Element, robot: RobotDescription) -> None:
    fp = robot.footprint
    z = robot.wheel_diameter_m / 2 + BODY_HEIGHT_M / 2
    if fp.radius_m is not None:
        x, y, size = fp.x_m, 0.0, {"kind": "cylinder", "radius": _num(fp.radius_m), "length": _num(BODY_HEIGHT_M)}
    else:
        if fp.length_m is not None and fp.width_m is not None:
            x, y, length, width = fp.x_m, 0.0, fp.length_m, fp.width_m
        else:
            xs, ys = [p[0] for p in fp.polygon_m or ()], [p[1] for p in fp.polygon_m or ()]
            x, y = (max(xs) + min(xs)) / 2, (max(ys) + min(ys)) / 2
            length, width = max(xs) - min(xs), max(ys) - min(ys)
        size = {"kind": "box", "size": _nums(length, width, BODY_HEIGHT_M)}
    for tag in ("visual", "collision"):
        _shape(base, tag, (x, y, z), (0.0, 0.0, 0.0), size)


def _wheel_link(root: ET.Element, name: str, radius: float, offsets: Sequence[float]) -> None:
    """A link drawing a wheel at each y offset (cylinders turned to lie along y)."""
    link = ET.SubElement(root, "link", name=name)
    for y in offsets:
        size = {"kind": "cylinder", "radius": _num(radius), "length": _num(WHEEL_WIDTH_M)}
        _shape(link, "visual", (0.0, y, 0.0), (math.pi / 2, 0.0, 0.0), size)


def _joint(root: ET.Element, name: str, kind: str, frame: StaticFrame) -> ET.Element:
    joint = ET.SubElement(root, "joint", name=name, type=kind)
    ET.SubElement(joint, "parent", link=frame.parent)
    ET.SubElement(joint, "child", link=frame.child)
    _origin(joint, (frame.x, frame.y, frame.z), (frame.roll, frame.pitch, frame.yaw))
    return joint


def _wheels(root: ET.Element, robot: RobotDescription, names: FrameNames) -> None:
    kin, joints = robot.kinematics(), joint_names(robot, names)
    r, half = robot.wheel_diameter_m / 2, robot.track_m / 2
    places: list[tuple[str, float, float, tuple[float, ...]]]
    if isinstance(kin, DiffDrive):
        places = [(joints[0], 0.0, half, (0.0,)), (joints[1], 0.0, -half, (0.0,))]
    else:
        places = [(joints[0], 0.0, 0.0, (half, -half)), (joints[1], robot.geometry.wheelbase_m, 0.0, (half, -half))]
    for joint_name, x, y, offsets in places:
        child = link_name(joint_name)
        _wheel_link(root, child, r, offsets)
        steering = joint_name == names.steering_joint and isinstance(kin, Ackermann)
        place = StaticFrame(names.base, child, x, y, r)
        joint = _joint(root, joint_name, "revolute" if steering else "continuous", place)
        ET.SubElement(joint, "axis", xyz="0 0 1" if steering else "0 1 0")
        if steering and robot.steering is not None:
            s = robot.steering
            lower, upper = math.radians(s.min_deg - s.center_deg), math.radians(s.max_deg - s.center_deg)
            # effort and velocity: required by URDF, unknown for a hobby servo (0: not given).
            ET.SubElement(joint, "limit", lower=_num(lower), upper=_num(upper), effort="0", velocity="0")


def build_urdf(robot: RobotDescription, names: FrameNames = DEFAULT_NAMES) -> str:
    """The URDF text of `robot` (deterministic: the same file and names give the same text)."""
    root = ET.Element("robot", name=robot.name)
    root.append(ET.Comment(f" {robot.name}: generated from its robot file by `roverlink robot urdf` "))
    base = ET.SubElement(root, "link", name=names.base)
    _body(base, robot)
    _wheels(root, robot, names)
    for frame in static_frames(robot, names):
        ET.SubElement(root, "link", name=frame.child)
        _joint(root, f"{frame.child}_joint", "fixed", frame)
    ET.indent(root, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
