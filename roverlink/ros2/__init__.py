"""The ROS 2 bridge: a RoverLink robot as a ROS 2 node (`roverlink ros2`; docs/ros2.md).

Only `roverlink.ros2.node`, `run`, `simulation`, `sensors` and `static_tf` import rclpy and the
message packages, and nothing imports them until `roverlink ros2` runs: the SDK and the other
commands never need ROS. `params`, `convert`, `driver`, `diagnostics`, `connection`, `frames` and
`urdf` (`roverlink robot urdf`) are plain Python.
"""

from __future__ import annotations

import importlib.util

INSTALL_HINT = (
    "the ROS 2 bridge needs rclpy and the ROS 2 message packages: source a ROS 2 installation "
    "(`source /opt/ros/humble/setup.bash` or `/opt/ros/jazzy/setup.bash`) before running `roverlink ros2`, "
    "from a venv made from the system's Python with --system-site-packages; or, on x86-64 Linux without ROS, install "
    "Jazzy's wheels with `pip install 'roverlink[ros2]'` (`roverlink doctor` says which applies here)"
)

REQUIRED_MODULES = ("rclpy", "geometry_msgs", "nav_msgs", "sensor_msgs", "diagnostic_msgs", "std_srvs")


def missing_modules() -> list[str]:
    """The ROS 2 Python packages the node needs that cannot be imported here."""
    return [name for name in REQUIRED_MODULES if importlib.util.find_spec(name) is None]
