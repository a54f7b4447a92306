"""Launch the RoverLink bridge with a parameters file (ROS 2 Jazzy; `ros2 launch roverlink.launch.py`).

    ros2 launch roverlink.launch.py url:=/dev/ttyACM0 params:=roverlink.yaml

The bridge is the `roverlink` command (pip install 'roverlink[ros2]', or into the Python of a ROS 2
installation), so it is started as a process rather than from a ROS package.
"""

from pathlib import Path

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.substitutions import LaunchConfiguration


def generate_launch_description() -> LaunchDescription:
    here = Path(__file__).resolve().parent
    return LaunchDescription(
        [
            DeclareLaunchArgument("url", default_value="/dev/ttyACM0"),
            DeclareLaunchArgument("params", default_value=str(here / "roverlink.yaml")),
            DeclareLaunchArgument("namespace", default_value="/"),
            ExecuteProcess(
                cmd=[
                    "roverlink",
                    "ros2",
                    "--url",
                    LaunchConfiguration("url"),
                    "--ros-args",
                    "--params-file",
                    LaunchConfiguration("params"),
                    "-r",
                    ["__ns:=", LaunchConfiguration("namespace")],
                ],
                output="screen",
                sigterm_timeout="5",
            ),
        ]
    )
