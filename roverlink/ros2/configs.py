"""Parameters files for a robot on ROS 2 Jazzy: the node's, SLAM Toolbox's and Nav2's, from its robot file.

    roverlink robot ros2-config my_robot.toml --out config/   # roverlink.yaml, slam_toolbox.yaml, nav2.yaml

The robot's facts (footprint, speed and acceleration limits, a car's wheelbase and steering range,
the lidar's model and range) come from the robot file; the frame names and the node's parameter
names from the node's parameter table (`params.SPECS`), the topic names from `TOPICS` (the names
the node publishes and subscribes; tests/roverlink/ros2 checks them against a running node).
examples/ros2/<robot>/ holds the reference robots' files, and a test fails when they drift from
what this writes. Plain Python: no ROS import.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Union

from host_sdk import RobotDescription
from protocol.robotfile import REFERENCES, reference_path
from roverlink.ros2.nav2config import nav2_params
from roverlink.ros2.params import SPECS, ParamValue
from roverlink.ros2.robotfacts import FILTERED_ODOM, MAP_FRAME, TOPICS, RobotFacts, frame

Scalar = bool | int | float | str
Tree = Mapping[str, Union["Tree", Scalar, Sequence[Scalar]]]

FILES = ("roverlink.yaml", "slam_toolbox.yaml", "nav2.yaml")


def node_params(robot: RobotDescription, facts: RobotFacts) -> dict[str, ParamValue]:
    """The node's parameters for `robot`: every one in SPECS, the robot's where it has them."""
    # An empty list has no type a parameters file can give it (ROS refuses it): such a parameter
    # keeps its default by being left out.
    values: dict[str, ParamValue] = {spec.name: spec.default for spec in SPECS if spec.default != []}
    if robot.name in REFERENCES and Path(robot.path).resolve() == reference_path(robot.name).resolve():
        values["profile"] = robot.name
    else:
        values["robot_file"] = str(Path(robot.path).resolve())
    values["odom_rate"] = round(facts.feedback_hz)
    values["lidar_url"] = facts.lidar_port
    values["lidar_model"] = facts.lidar_model
    if robot.imu is not None:
        values["imu_url"] = robot.imu.port or ""
    return values


def slam_params(facts: RobotFacts) -> dict[str, Scalar]:
    """SLAM Toolbox (online async) on the node's frames and scan."""
    return {
        "solver_plugin": "solver_plugins::CeresSolver",
        "ceres_linear_solver": "SPARSE_NORMAL_CHOLESKY",
        "ceres_preconditioner": "SCHUR_JACOBI",
        "ceres_trust_strategy": "LEVENBERG_MARQUARDT",
        "ceres_dogleg_type": "TRADITIONAL_DOGLEG",
        "ceres_loss_function": "None",
        "odom_frame": frame("odom_frame"),
        "map_frame": MAP_FRAME,
        "base_frame": frame("base_frame"),
        "scan_topic": TOPICS["scan"],
        "mode": "mapping",
        "use_map_saver": True,
        "debug_logging": False,
        "throttle_scans": 1,
        "transform_publish_period": 0.02,
        "map_update_interval": 5.0,
        "resolution": 0.05,
        "max_laser_range": facts.lidar_range_m[1],
        "minimum_time_interval": 0.5,
        "transform_timeout": 0.2,
        "tf_buffer_duration": 30.0,
        "stack_size_to_use": 40_000_000,
        "enable_interactive_mode": True,
        "use_scan_matching": True,
        "use_scan_barycenter": True,
        # A small robot: a new scan every 20 cm or 0.3 rad.
        "minimum_travel_distance": 0.2,
        "minimum_travel_heading": 0.3,
        "scan_buffer_size": 10,
        "scan_buffer_maximum_scan_distance": facts.lidar_range_m[1],
        "link_match_minimum_response_fine": 0.1,
        "link_scan_maximum_distance": 1.5,
        "loop_search_maximum_distance": 3.0,
        "do_loop_closing": True,
        "loop_match_minimum_chain_size": 10,
        "loop_match_maximum_variance_coarse": 3.0,
        "loop_match_minimum_response_coarse": 0.35,
        "loop_match_minimum_response_fine": 0.45,
    }


def _scalar(value: Scalar) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        # 1.0e-10, not 1e-10: YAML 1.1 readers take the latter for a string
        return f"{value:.1e}" if 0 < abs(value) < 1e-3 else repr(round(value, 4))
    plain = value and all(c.isalnum() or c in "_/:.-" for c in value) and value not in ("true", "false", "null")
    plain = plain and value[0] not in "-."
    return value if plain and not value[0].isdigit() else json.dumps(value)


def to_yaml(tree: Tree, indent: int = 0) -> str:
    """`tree` as YAML (block mappings, flow lists of scalars), in the order given."""
    lines = []
    pad = "  " * indent
    for key, value in tree.items():
        if isinstance(value, Mapping):
            lines.append(f"{pad}{key}:\n{to_yaml(value, indent + 1)}")
        elif isinstance(value, (list, tuple)):
            lines.append(f"{pad}{key}: [{', '.join(_scalar(v) for v in value)}]")
        else:
            assert isinstance(value, (bool, int, float, str))
            lines.append(f"{pad}{key}: {_scalar(value)}")
    return "\n".join(lines) + ("\n" if indent == 0 else "")


def render(
    robot: RobotDescription, max_speed_m_s: float | None = None, odom_topic: str = TOPICS["odom"]
) -> dict[str, str]:
    """File name -> text of the three parameters files for `robot` (`odom_topic`: Nav2's odometry,
    the node's odom or an EKF's odometry/filtered)."""
    facts = RobotFacts.of(robot, max_speed_m_s)
    header = (
        f"# {{what}} for the robot {facts.name}, written by `roverlink robot ros2-config` from "
        f"{facts.source}\n# (docs/ros2.md, SLAM and Nav2): change the robot file and write it again.\n"
    )
    node = {"/**/roverlink": {"ros__parameters": node_params(robot, facts)}}
    slam = {"slam_toolbox": {"ros__parameters": slam_params(facts)}}
    return {
        "roverlink.yaml": header.format(what="The roverlink node's parameters") + to_yaml(node),
        "slam_toolbox.yaml": header.format(what="SLAM Toolbox (online async) parameters") + to_yaml(slam),
        "nav2.yaml": header.format(what="Nav2 parameters") + to_yaml(nav2_params(facts, odom_topic)),
    }


def write(
    robot: RobotDescription, out: Path, max_speed_m_s: float | None = None, odom_topic: str = TOPICS["odom"]
) -> list[Path]:
    """Write the three files into `out` (made if missing); returns their paths."""
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, text in render(robot, max_speed_m_s, odom_topic).items():
        path = out / name
        path.write_text(text, encoding="utf-8")
        paths.append(path)
    return paths


def warnings(robot: RobotDescription, odom_topic: str) -> list[str]:
    """What the files would get wrong for `robot`: Nav2 on odometry/filtered, which only an IMU
    (the node's EKF, or robot_localization fusing `imu`) publishes."""
    if odom_topic == FILTERED_ODOM and robot.imu is None:
        return [
            f"--odom-topic {FILTERED_ODOM}: {robot.path} has no [sensors.imu], so nothing publishes "
            f"{FILTERED_ODOM} (the node fuses the IMU's gyro into it) and Nav2 gets no odometry: add the IMU "
            f"to the robot file, or keep --odom-topic {TOPICS['odom']}"
        ]
    return []
