"""The ROS 2 parameters files `roverlink robot ros2-config` writes (examples/ros2/<robot>/): no drift,
the node's names, the robot file's facts, and only parameter names Jazzy's packages know.

Nav2 and SLAM Toolbox cannot run here (no PyPI wheels); what is checked instead: every file parses,
every frame and topic is the node's (params.SPECS, robotfacts.TOPICS), the footprint is the robot
file's, the car's tightest turn its wheelbase and steering range give, and every key is a parameter
the Jazzy sources declare (jazzy_param_names.toml, written by tools/ros2_param_names.py).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

from host_sdk import RobotDescription
from protocol.robotfile import REFERENCES, reference_path
from protocol.sensors import DEVICES, LidarSpec
from protocol.toml import tomllib
from roverlink.cli import main as cli_main
from roverlink.ros2.configs import FILES, render
from roverlink.ros2.params import BY_NAME, BridgeParams
from roverlink.ros2.robotfacts import (
    FILTERED_ODOM,
    MAP_FRAME,
    MAX_TURN_PER_SCAN_RAD,
    TOPICS,
    RobotFacts,
    footprint_polygon,
)

ROOT = Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "examples" / "ros2"
KNOWN = tomllib.loads((Path(__file__).with_name("jazzy_param_names.toml")).read_text(encoding="utf-8"))

NODE_PACKAGES = {
    "bt_navigator": ("nav2_bt_navigator", "nav2_behavior_tree"),
    "controller_server": ("nav2_controller",),
    "local_costmap": ("nav2_costmap_2d",),
    "global_costmap": ("nav2_costmap_2d",),
    "planner_server": ("nav2_planner",),
    "smoother_server": ("nav2_smoother",),
    "behavior_server": ("nav2_behaviors",),
    "waypoint_follower": ("nav2_waypoint_follower",),
    "velocity_smoother": ("nav2_velocity_smoother",),
    "collision_monitor": ("nav2_collision_monitor",),
    "docking_server": ("nav2_docking",),
    "route_server": ("nav2_route",),
    "slam_toolbox": ("slam_toolbox",),
}
"""The package that declares a node's own parameters (each plugin's: its `plugin` value's namespace)."""
PLUGIN_PACKAGES = {"opennav_docking": "nav2_docking"}
"""A plugin namespace that is not its package's name."""


def _files(robot: str) -> dict[str, Any]:
    return {name: yaml.safe_load((EXAMPLES / robot / name).read_text(encoding="utf-8")) for name in FILES}


def _frame(name: str) -> str:
    value = BY_NAME[name].default
    assert isinstance(value, str)
    return value


def _leaves(tree: dict[str, Any], packages: tuple[str, ...], path: str) -> Iterator[tuple[str, str, tuple[str, ...]]]:
    """(path, key, packages that may declare it) for every parameter under `tree`."""
    plugin = tree.get("plugin")
    if isinstance(plugin, str):
        namespace = plugin.split("::")[0]
        packages = (PLUGIN_PACKAGES.get(namespace, namespace),)
    for key, value in tree.items():
        if isinstance(value, dict):
            yield from _leaves(value, packages, f"{path}.{key}")
        else:
            yield f"{path}.{key}", key, packages


def _parameters(document: dict[str, Any]) -> Iterator[tuple[str, dict[str, Any]]]:
    """(node, its ros__parameters) of a parameters file (costmaps nest one level deeper)."""
    for node, body in document.items():
        if "ros__parameters" in body:
            yield node, body["ros__parameters"]
        else:
            for inner, inner_body in body.items():
                yield inner, inner_body["ros__parameters"]


@pytest.mark.parametrize("robot", REFERENCES)
def test_the_committed_files_are_what_the_robot_file_gives(robot: str) -> None:
    written = render(RobotDescription.load(reference_path(robot)))
    for name in FILES:
        committed = (EXAMPLES / robot / name).read_text(encoding="utf-8")
        assert committed == written[name], f"examples/ros2/{robot}/{name}: run `roverlink robot ros2-config`"


@pytest.mark.parametrize("robot", REFERENCES)
def test_every_key_is_a_parameter_jazzy_declares(robot: str) -> None:
    files = _files(robot)
    unknown = []
    for name in ("nav2.yaml", "slam_toolbox.yaml"):
        for node, params in _parameters(files[name]):
            assert node in NODE_PACKAGES, f"{name}: {node} is no node navigation_launch.py or SLAM Toolbox starts"
            for path, key, packages in _leaves(params, NODE_PACKAGES[node], node):
                known = {n for p in packages for n in KNOWN[p]["names"]} | set(KNOWN["nav2_util"]["names"])
                if key not in known:
                    unknown.append(f"{name}: {path} (not in {', '.join(packages)})")
    assert unknown == []


def test_the_check_finds_a_misspelt_parameter() -> None:
    tree = {"FollowPath": {"plugin": "nav2_mppi_controller::MPPIController", "vx_maxx": 0.5}, "controller_frequency": 1}
    leaves = {key: packages for _, key, packages in _leaves(tree, ("nav2_controller",), "controller_server")}
    assert leaves == {
        "plugin": ("nav2_mppi_controller",),
        "vx_maxx": ("nav2_mppi_controller",),
        "controller_frequency": ("nav2_controller",),
    }
    assert "vx_maxx" not in KNOWN["nav2_mppi_controller"]["names"]
    assert "vx_max" in KNOWN["nav2_mppi_controller"]["names"]


@pytest.mark.parametrize("robot", REFERENCES)
def test_every_plugin_list_names_configured_sections(robot: str) -> None:
    for node, params in _parameters(_files(robot)["nav2.yaml"]):
        for key in (
            "controller_plugins",
            "planner_plugins",
            "smoother_plugins",
            "behavior_plugins",
            "plugins",
            "progress_checker_plugins",
            "goal_checker_plugins",
            "navigators",
            "polygons",
            "dock_plugins",
        ):
            for name in params.get(key, []):
                assert "plugin" in params[name] or "type" in params[name], f"{node}.{key}: {name}"
        critics = params.get("FollowPath", {}).get("critics", [])
        assert all(c in params["FollowPath"] for c in critics)


@pytest.mark.parametrize("robot", REFERENCES)
def test_frames_and_topics_are_the_nodes(robot: str) -> None:
    files = _files(robot)
    slam = files["slam_toolbox.yaml"]["slam_toolbox"]["ros__parameters"]
    odom, base = _frame("odom_frame"), _frame("base_frame")
    assert (slam["odom_frame"], slam["base_frame"], slam["map_frame"]) == (odom, base, MAP_FRAME)
    assert slam["scan_topic"] == TOPICS["scan"]
    nav = dict(_parameters(files["nav2.yaml"]))
    assert nav["local_costmap"]["global_frame"] == odom and nav["global_costmap"]["global_frame"] == MAP_FRAME
    for node in ("local_costmap", "global_costmap", "bt_navigator"):
        assert nav[node]["robot_base_frame"] == base
    for costmap in ("local_costmap", "global_costmap"):
        assert nav[costmap]["obstacle_layer"]["scan"]["topic"] == TOPICS["scan"]
    assert nav["bt_navigator"]["odom_topic"] == nav["velocity_smoother"]["odom_topic"] == TOPICS["odom"]
    monitor = nav["collision_monitor"]
    assert (monitor["base_frame_id"], monitor["odom_frame_id"]) == (base, odom)
    assert monitor["cmd_vel_out_topic"] == TOPICS["cmd_vel"] and monitor["scan"]["topic"] == TOPICS["scan"]
    stamped = BY_NAME["use_stamped_vel"].default
    assert all(p["enable_stamped_cmd_vel"] == stamped for p in nav.values() if "enable_stamped_cmd_vel" in p)
    assert nav["velocity_smoother"]["enable_stamped_cmd_vel"] == stamped


@pytest.mark.parametrize("robot", REFERENCES)
def test_the_node_file_is_a_valid_parameter_set_for_the_robot(robot: str) -> None:
    values = _files(robot)["roverlink.yaml"]["/**/roverlink"]["ros__parameters"]
    params = BridgeParams.from_values(values)  # every name known, every value in range
    described = RobotDescription.load(reference_path(robot))
    assert params.profile == robot and params.odom_rate == round(described.feedback.rate_hz)
    if described.lidar is not None:
        assert params.lidar_model == described.lidar.model and params.lidar_url == (described.lidar.port or "")
    assert params.publish_static_tf  # the file alone places the sensors; bringup.launch.py turns it off


@pytest.mark.parametrize("robot", REFERENCES)
def test_footprint_is_the_robot_files(robot: str) -> None:
    described = RobotDescription.load(reference_path(robot))
    radius, centre = described.footprint.disc()
    for costmap in ("local_costmap", "global_costmap"):
        params = _files(robot)["nav2.yaml"][costmap][costmap]["ros__parameters"]
        if centre == 0:
            assert params["robot_radius"] == pytest.approx(radius) and "footprint" not in params
            continue
        points = yaml.safe_load(params["footprint"])
        # A disc off base_link: a polygon whose every side touches the disc, so it covers it exactly.
        for (x0, y0), (x1, y1) in zip(points, points[1:] + points[:1], strict=True):
            distance = abs((x1 - x0) * (y0 - 0) - (x0 - centre) * (y1 - y0)) / math.hypot(x1 - x0, y1 - y0)
            assert distance == pytest.approx(radius, abs=1e-3)
        assert params["inflation_layer"]["inflation_radius"] > max(math.hypot(x, y) for x, y in points)


def test_a_box_or_polygon_footprint_is_taken_as_it_is(tmp_path: Path) -> None:
    text = reference_path("diffdrive-tb6612").read_text(encoding="utf-8")
    start = text.index("[footprint]")
    end = text.index("\n[", start) + 1
    box = text[:start] + "[footprint]\nlength_m = 0.3\nwidth_m = 0.2\nx_m = 0.05\n\n" + text[end:]
    (tmp_path / "box.toml").write_text(box, encoding="utf-8")
    assert footprint_polygon(RobotDescription.load(tmp_path / "box.toml")) == (
        (0.2, 0.1),
        (-0.1, 0.1),
        (-0.1, -0.1),
        (0.2, -0.1),
    )
    polygon = text[:start] + "[footprint]\npolygon_m = [[0.2, 0.1], [-0.1, 0.1], [-0.1, -0.12], [0.2, -0.1]]\n\n"
    (tmp_path / "poly.toml").write_text(polygon + text[end:], encoding="utf-8")
    facts = RobotFacts.of(RobotDescription.load(tmp_path / "poly.toml"))
    assert facts.footprint == ((0.2, 0.1), (-0.1, 0.1), (-0.1, -0.12), (0.2, -0.1))


def test_the_car_turns_no_tighter_than_its_wheelbase_and_steering_allow() -> None:
    car = RobotDescription.load(reference_path("picar"))
    nav = dict(_parameters(_files("picar")["nav2.yaml"]))
    mppi = nav["controller_server"]["FollowPath"]
    # picar.toml: servo 65..125 deg around 90 in 15 deg steps reaches -25..+30 deg: 25 deg both ways.
    radius = car.geometry.wheelbase_m / math.tan(math.radians(25))
    assert mppi["motion_model"] == "Ackermann"
    assert mppi["AckermannConstraints"]["min_turning_r"] == pytest.approx(radius, abs=1e-4)
    planner = nav["planner_server"]["GridBased"]
    assert planner["plugin"] == "nav2_smac_planner::SmacPlannerHybrid"
    assert planner["minimum_turning_radius"] == pytest.approx(radius, abs=1e-4)
    assert mppi["wz_max"] == pytest.approx(car.limits.max_wheel_speed_m_s / radius, abs=1e-3)


@pytest.mark.parametrize("robot", ["diffdrive-tb6612", "diffdrive-bts7960"])
def test_speed_and_acceleration_are_the_robot_files(robot: str) -> None:
    described = RobotDescription.load(reference_path(robot))
    lim = described.limits
    nav = dict(_parameters(_files(robot)["nav2.yaml"]))
    mppi, smoother = nav["controller_server"]["FollowPath"], nav["velocity_smoother"]
    assert mppi["motion_model"] == "DiffDrive" and "AckermannConstraints" not in mppi
    assert (mppi["vx_max"], mppi["ax_max"], mppi["ax_min"]) == (
        lim.max_wheel_speed_m_s,
        lim.accel_m_s2,
        -lim.decel_m_s2,
    )
    turn = 2 * lim.max_wheel_speed_m_s / described.track_m  # in place, both wheels at their limit
    lidar = DEVICES[described.lidar.model if described.lidar else BY_NAME["lidar_model"].default]
    assert isinstance(lidar, LidarSpec)
    turn = min(turn, MAX_TURN_PER_SCAN_RAD * lidar.scan_hz)  # a scan smeared over a fast turn matches badly
    assert mppi["wz_max"] == pytest.approx(turn, abs=1e-3)
    assert smoother["max_velocity"] == pytest.approx([lim.max_wheel_speed_m_s, 0.0, turn], abs=1e-3)
    assert smoother["max_accel"][0] == lim.accel_m_s2 and smoother["max_decel"][0] == -lim.decel_m_s2
    assert nav["planner_server"]["GridBased"]["plugin"] == "nav2_navfn_planner::NavfnPlanner"


def test_doubles_are_written_as_floats() -> None:
    # Nav2 refuses 1 for a double parameter: the writer must keep 1.0.
    text = (EXAMPLES / "diffdrive-bts7960" / "nav2.yaml").read_text(encoding="utf-8")
    nav = dict(_parameters(yaml.safe_load(text)))
    assert isinstance(nav["velocity_smoother"]["max_velocity"][0], float)
    assert isinstance(nav["smoother_server"]["simple_smoother"]["tolerance"], float)
    assert isinstance(nav["controller_server"]["FollowPath"]["batch_size"], int)


def test_the_command_writes_a_users_robot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    mine = tmp_path / "mine.toml"
    assert cli_main(["robot", "new", str(mine), "--from", "diffdrive-tb6612"]) == 0
    out = tmp_path / "config"
    args = ["robot", "ros2-config", str(mine), "--out", str(out), "--max-speed", "0.3", "--odom-topic", FILTERED_ODOM]
    assert cli_main(args) == 0
    assert sorted(p.name for p in out.iterdir()) == sorted(FILES)
    node = yaml.safe_load((out / "roverlink.yaml").read_text())["/**/roverlink"]["ros__parameters"]
    assert node["robot_file"] == str(mine.resolve()) and node["profile"] == ""
    nav = dict(_parameters(yaml.safe_load((out / "nav2.yaml").read_text())))
    assert nav["controller_server"]["FollowPath"]["vx_max"] == 0.3
    assert nav["bt_navigator"]["odom_topic"] == nav["velocity_smoother"]["odom_topic"] == FILTERED_ODOM
    assert cli_main(["robot", "ros2-config", str(tmp_path / "missing.toml"), "--out", str(out)]) == 2
    assert cli_main(["robot", "ros2-config", str(mine), "--out", str(out), "--max-speed", "0"]) == 2
    assert "--max-speed 0: must be > 0 m/s" in capsys.readouterr().err


def test_odometry_filtered_without_an_imu_is_warned_about(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Nav2 on odometry/filtered needs an IMU to fuse: the PiCar has none, the TB6612 robot one."""
    for robot, warned in (("picar", True), ("diffdrive-tb6612", False)):
        args = ["robot", "ros2-config", robot, "--out", str(tmp_path / robot), "--odom-topic", FILTERED_ODOM]
        assert cli_main(args) == 0
        err = capsys.readouterr().err
        assert ("has no [sensors.imu], so nothing publishes odometry/filtered" in err) is warned, err
    assert cli_main(["robot", "ros2-config", "picar", "--out", str(tmp_path / "odom")]) == 0
    assert capsys.readouterr().err == ""


def test_every_reference_robot_has_its_parameters_folder_and_no_other() -> None:
    """The ROS 2 package installs the folders it finds; a reference robot added without its files
    (or a folder left behind by a removed one) is named here."""
    folders = sorted(p.parent.name for p in EXAMPLES.glob("*/roverlink.yaml"))
    assert folders == sorted(REFERENCES), (
        "run `roverlink robot ros2-config protocol/robots/<name>.toml --out examples/ros2/<name>`"
    )
