"""What `roverlink doctor` says: one line per piece this host's features rest on (host_sdk.hostinfo's
probes), and for a piece that is missing or wrong the one-line fix for this platform (a
Raspberry Pi, a Jetson and its JetPack, Ubuntu, Debian)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from host_sdk import hostinfo
from host_sdk.hostinfo import Machine, OpenCv, PythonInfo, Ros2
from roverlink.ros2 import missing_modules

SYSTEM_VENV = "SYSTEM_SITE_PACKAGES=1 PYTHON=/usr/bin/python3 bash scripts/venv.sh"
"""The checkout's venv made from the system's Python, seeing its packages (README)."""
ROS_FOR = {("ubuntu", "22.04"): "humble", ("ubuntu", "24.04"): "jazzy"}


@dataclass(frozen=True, slots=True)
class Finding:
    name: str
    found: str
    fix: str | None = None
    """None: nothing to do."""


def _where(location: str | None, from_system: bool) -> str:
    return f"{'system' if from_system else 'pip'}, {location}" if location else "?"


def check_python(m: Machine, py: PythonInfo, cv: OpenCv) -> Finding:
    kind = "venv" if py.venv else "no venv"
    if py.venv:
        kind += ", sees the system's packages" if py.system_site_packages else ", without the system's packages"
    found = f"{py.text} {py.executable} ({kind})"
    system_wanted = m.kind in ("raspberry-pi", "jetson") or cv.system_copy is not None
    if py.venv and not py.system_site_packages and system_wanted:
        return Finding("Python", found, f"this venv cannot see the system's OpenCV, picamera2 and ROS: {SYSTEM_VENV}")
    return Finding("Python", found)


def check_opencv(m: Machine, py: PythonInfo, cv: OpenCv) -> Finding:
    mod = cv.module
    if mod.problem is not None and mod.version is None and mod.location is not None:
        return Finding("OpenCV", "installed, but built for another numpy", mod.problem)
    if cv.build is None:
        return Finding("OpenCV", mod.problem or "not installed", _opencv_install(m, cv))
    b = cv.build
    yes = {True: "yes", False: "no"}
    found = f"{b.version} ({_where(mod.location, mod.from_system)}): GStreamer {yes[b.gstreamer]}, V4L2 {yes[b.v4l2]}"
    if b.gstreamer or m.kind == "other":
        return Finding("OpenCV", found)
    if cv.system_copy is not None and not mod.from_system:
        if py.system_site_packages:
            fix = (
                f"pip uninstall opencv-python-headless: the system's OpenCV ({cv.system_copy}) is then the one imported"
            )
        else:
            fix = f"the system's OpenCV ({cv.system_copy}) is for the system's Python: {SYSTEM_VENV}, without vision"
        return Finding("OpenCV", found, fix)
    return Finding("OpenCV", found, f"for CSI cameras and pipelines: {_opencv_install(m, cv)}")


def _opencv_install(m: Machine, cv: OpenCv) -> str:
    if m.kind == "jetson":
        if cv.system_copy is not None:
            return f"JetPack's OpenCV ({cv.system_copy}) is the system Python's: {SYSTEM_VENV}"
        return f"install JetPack's OpenCV (sudo apt install nvidia-opencv), then {SYSTEM_VENV}"
    if m.kind in ("raspberry-pi", "debian", "ubuntu"):
        if cv.system_copy is not None:
            return f"the system's OpenCV ({cv.system_copy}) is there: {SYSTEM_VENV}"
        return (
            f"sudo apt install python3-opencv gstreamer1.0-plugins-good, then {SYSTEM_VENV}; "
            "or pip install 'roverlink[vision]' (no GStreamer) for a USB webcam or MJPEG"
        )
    return "pip install 'roverlink[vision]'"


def check_picamera2(m: Machine, picam: hostinfo.Module) -> Finding:
    if picam.problem is None:
        return Finding("picamera2", f"{picam.version} ({_where(picam.location, picam.from_system)})")
    if picam.location is not None:  # there, but built for another numpy
        return Finding("picamera2", "installed, but it (or its simplejpeg) is built for another numpy", picam.problem)
    if m.kind != "raspberry-pi":
        return Finding("picamera2", "not installed (the Raspberry Pi camera's route: not needed here)")
    return Finding("picamera2", picam.problem, f"sudo apt install python3-picamera2, then {SYSTEM_VENV}")


def check_ros2(m: Machine, py: PythonInfo, ros: Ros2) -> Finding:
    rclpy = ros.rclpy
    if ros.built_for is not None:
        fix = (
            f"ROS 2 {ros.distro or ''}'s rclpy is built for Python {ros.built_for}: make the venv from the system's "
            f"python{ros.built_for}: {SYSTEM_VENV} (docs/ros2.md)"
        )
        return Finding("ROS 2", f"{ros.distro or '?'}: rclpy {rclpy.version} ({rclpy.location}), {rclpy.problem}", fix)
    if rclpy.location is not None:
        found = f"{ros.distro or '?'}: rclpy {rclpy.version} ({rclpy.location})"
        missing = missing_modules()
        if not missing:
            return Finding("ROS 2", found)
        names = " ".join(f"ros-{ros.distro or '$ROS_DISTRO'}-{n.replace('_', '-')}" for n in missing)
        fix = f"sudo apt install {names}" if ros.installed else "pip install 'roverlink[ros2]'"
        return Finding("ROS 2", f"{found}; missing {', '.join(missing)}", fix)
    if ros.installed:
        distro = ros.installed[-1]
        return Finding(
            "ROS 2",
            f"rclpy not found ({', '.join(ros.installed)} in /opt/ros)",
            f"source /opt/ros/{distro}/setup.bash before running `roverlink ros2`",
        )
    return Finding("ROS 2", "rclpy not found", _ros_install(m))


def _ros_install(m: Machine) -> str:
    if m.kind == "jetson" and m.jetpack in ("4", "5"):
        return (
            f"JetPack {m.jetpack}'s Ubuntu has no ROS 2 on Python 3.10 or later: run the node in the "
            "ros:humble-ros-base container (docs/ros2.md#jetpack-5-and-46)"
        )
    distro = "humble" if m.kind == "jetson" else ROS_FOR.get((m.os_id, m.os_version))
    if distro is not None:
        return (
            f"sudo apt install ros-{distro}-ros-base (the ROS 2 apt repository), source /opt/ros/{distro}/setup.bash, "
            f"then {SYSTEM_VENV} (docs/ros2.md)"
        )
    if m.kind == "raspberry-pi":
        return "Raspberry Pi OS has no ROS 2 packages: Ubuntu 24.04 on the Pi, or the ros:jazzy-ros-base container"
    return "pip install 'roverlink[ros2]' (ROS 2 Jazzy's wheels, x86-64 Linux; docs/ros2.md)"


def check_serial(ports: list[hostinfo.PortAccess], user: str) -> list[Finding]:
    if not ports:
        return [Finding("serial", "no serial ports (the board's USB cable?)")]
    out = []
    for p in ports:
        name = f"serial {p.port.device}"
        what = f"{p.port.description} ({p.port.why})"
        if p.allowed:
            out.append(Finding(name, f"{what}: read and write"))
        elif p.listed and not p.in_group:
            out.append(
                Finding(name, f"{what}: no access yet", f"{user} is in {p.group} since the last login: log in again")
            )
        elif p.group is not None:
            fix = f"sudo usermod -aG {p.group} {user}, then log in again"
            out.append(Finding(name, f"{what}: no access (group {p.group})", fix))
        else:
            out.append(Finding(name, f"{what}: no access", "check the device node's owner and mode (ls -l)"))
    return out


def findings(root: Path = Path("/")) -> list[Finding]:
    m, py = hostinfo.machine(root), hostinfo.python_info()
    cv, numpy = hostinfo.opencv(root), hostinfo.numpy_module()
    board = f", {m.board}" if m.board else ""
    jetpack = f", JetPack {m.jetpack} (L4T {m.l4t})" if m.l4t else ""
    return [
        Finding("system", f"{m.os_name}{board}{jetpack}"),
        check_python(m, py, cv),
        Finding("numpy", f"{numpy.version} ({_where(numpy.location, numpy.from_system)})", numpy.problem),
        check_opencv(m, py, cv),
        check_picamera2(m, hostinfo.picamera2_module()),
        check_ros2(m, py, hostinfo.ros2(root)),
        *check_serial(hostinfo.serial_access(), hostinfo.user_name()),
    ]
