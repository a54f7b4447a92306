"""SLAM and navigation on a RoverLink robot (ROS 2 Jazzy; docs/ros2.md, SLAM and Nav2).

    ros2 launch roverlink_ros bringup.launch.py robot:=diffdrive-bts7960 url:=/dev/ttyACM0
    ros2 launch roverlink_ros bringup.launch.py robot:=my_robot.toml config:=my_config/

Starts the roverlink node (the ros2/roverlink_ros package's `roverlink` executable) with the
robot's parameters, robot_state_publisher with the robot's URDF (written by `roverlink robot urdf`
at launch), SLAM Toolbox (online async) and Nav2 (nav2_bringup's navigation_launch.py).

`robot` is a reference robot (picar, diffdrive-tb6612, diffdrive-bts7960: their parameters files
are the folders next to this file, or config/<robot> of the installed package) or a robot file;
`config` is a folder with roverlink.yaml, slam_toolbox.yaml and nav2.yaml (`roverlink robot
ros2-config FILE --out FOLDER` writes them); without it a robot file's are written at launch. The
`roverlink` command must be on PATH (the virtual environment RoverLink is installed in).
"""

import subprocess
import tempfile
from pathlib import Path

from ament_index_python.packages import get_package_share_directory
from launch import LaunchContext, LaunchDescription
from launch.actions import DeclareLaunchArgument, IncludeLaunchDescription, OpaqueFunction
from launch.launch_description_sources import PythonLaunchDescriptionSource
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

HERE = Path(__file__).resolve().parent
FILES = ("roverlink.yaml", "slam_toolbox.yaml", "nav2.yaml")


def _roverlink(*args: str) -> None:
    subprocess.run(["roverlink", *args], check=True)


def _is_reference(robot: str) -> bool:
    """A reference robot's name (`roverlink robot new --from` knows them), not a robot file's path."""
    return not robot.endswith(".toml") and "/" not in robot


def _robot_file(robot: str, work: Path) -> str:
    """The robot file: a reference robot's as `roverlink robot new` copies it, or the one given."""
    if not _is_reference(robot):
        return str(Path(robot).expanduser().resolve())
    path = work / f"{robot}.toml"
    _roverlink("robot", "new", str(path), "--from", robot, "--force")
    return str(path)


def _config(robot: str, config: str, robot_file: str, work: Path) -> Path:
    """The folder with the three parameters files."""
    if config:
        return Path(config).expanduser().resolve()
    for folder in (HERE / robot, HERE.parent / "config" / robot):
        if _is_reference(robot) and all((folder / name).is_file() for name in FILES):
            return folder
    _roverlink("robot", "ros2-config", robot_file, "--out", str(work))
    return work


def _setup(context: LaunchContext) -> list:
    robot = LaunchConfiguration("robot").perform(context)
    work = Path(tempfile.mkdtemp(prefix="roverlink-bringup-"))
    robot_file = _robot_file(robot, work)
    config = _config(robot, LaunchConfiguration("config").perform(context), robot_file, work)
    urdf = work / "robot.urdf"
    _roverlink("robot", "urdf", robot_file, "-o", str(urdf))
    sim_time = LaunchConfiguration("use_sim_time")
    slam = Path(get_package_share_directory("slam_toolbox")) / "launch" / "online_async_launch.py"
    nav2 = Path(get_package_share_directory("nav2_bringup")) / "launch" / "navigation_launch.py"
    return [
        Node(
            package="roverlink_ros",
            executable="roverlink",
            name="roverlink",
            output="screen",
            # robot_state_publisher publishes the URDF's fixed joints: the node does not.
            parameters=[
                str(config / "roverlink.yaml"),
                {"url": LaunchConfiguration("url"), "publish_static_tf": False},
            ],
            sigterm_timeout="5",
        ),
        Node(
            package="robot_state_publisher",
            executable="robot_state_publisher",
            name="robot_state_publisher",
            output="screen",
            parameters=[{"robot_description": urdf.read_text(encoding="utf-8"), "use_sim_time": sim_time}],
        ),
        IncludeLaunchDescription(
            PythonLaunchDescriptionSource(str(slam)),
            launch_arguments={"slam_params_file": str(config / "slam_toolbox.yaml"), "use_sim_time": sim_time}.items(),
        ),
        IncludeLaunchDescription(
            PythonLaunchDescriptionSource(str(nav2)),
            launch_arguments={
                "params_file": str(config / "nav2.yaml"),
                "use_sim_time": sim_time,
                "autostart": "true",
            }.items(),
        ),
    ]


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "robot", default_value="diffdrive-bts7960", description="reference robot or robot file"
            ),
            DeclareLaunchArgument("config", default_value="", description="folder of the three parameters files"),
            DeclareLaunchArgument("url", default_value="/dev/ttyACM0", description="the board's port or URL"),
            DeclareLaunchArgument("use_sim_time", default_value="false"),
            OpaqueFunction(function=_setup),
        ]
    )
