"""What this host has for RoverLink: the machine and its Python, numpy, OpenCV and what its build
opens, picamera2, ROS 2's rclpy, and the serial ports with this user's access to them.

    from host_sdk import hostinfo
    cv = hostinfo.opencv()
    if cv.build is None or not cv.build.gstreamer: ...   # no CSI pipeline with this OpenCV

Each probe only looks (rclpy is found, not imported); `roverlink doctor` prints them all with the
fix for each missing piece on this platform. A module built for another numpy is reported, not
raised (`Module.problem`).
"""

from host_sdk.hostinfo.machine import Machine, PythonInfo, machine, python_info
from host_sdk.hostinfo.modules import Module, OpenCv, Ros2, numpy_module, opencv, picamera2_module, ros2
from host_sdk.hostinfo.serial_access import PortAccess, port_access, serial_access, user_name

__all__ = [
    "Machine",
    "Module",
    "OpenCv",
    "PortAccess",
    "PythonInfo",
    "Ros2",
    "machine",
    "numpy_module",
    "opencv",
    "picamera2_module",
    "port_access",
    "python_info",
    "ros2",
    "serial_access",
    "user_name",
]
