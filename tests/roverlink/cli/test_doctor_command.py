"""`roverlink doctor`: every piece named on this machine, and on the platforms users have (their
probes stood in for) the one-line fix for each missing or wrong piece."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from host_sdk import hostinfo
from host_sdk.hostinfo import Machine, Module, OpenCv, PortAccess, PythonInfo, Ros2
from host_sdk.ports import PortInfo
from host_sdk.sensors.camera.pipelines import OpenCvBuild
from roverlink import doctor
from roverlink.cli import main

JETSON = Machine("ubuntu", "22.04", "Ubuntu 22.04.4 LTS", "NVIDIA Jetson Orin Nano Developer Kit", "36.3.0")
JETSON_NANO = Machine("ubuntu", "18.04", "Ubuntu 18.04.6 LTS", "NVIDIA Jetson Nano Developer Kit", "32.7.4")
PI = Machine("debian", "12", "Debian GNU/Linux 12 (bookworm)", "Raspberry Pi 5 Model B Rev 1.0", None)
UBUNTU = Machine("ubuntu", "22.04", "Ubuntu 22.04.4 LTS", None, None)
PYENV = PythonInfo(
    (3, 11, 7), "/home/me/rl/.venv/bin/python", True, False, "/home/me/.pyenv/versions/3.11.7/bin/python3.11"
)
SYSTEM = PythonInfo((3, 10, 12), "/home/me/rl/.venv/bin/python", True, True, "/usr/bin/python3.10")
NO_CV = OpenCv(Module("cv2", None, None, "not installed"), None, None)
JETPACK_CV = "/usr/lib/python3.10/dist-packages/cv2"
NUMPY = Module("numpy", "1.21.5", "/usr/lib/python3/dist-packages")
NO_ROS = Ros2(None, Module("rclpy", None, None, "not found"), None, ())
ABI = "picamera2 (its simplejpeg, /usr/lib/python3/dist-packages) cannot be loaded with numpy 2.2.6 (...): ...; fix"


def _stand_in(monkeypatch: pytest.MonkeyPatch, m: Machine, py: PythonInfo, **probes: object) -> None:
    monkeypatch.setattr(hostinfo, "machine", lambda root: m)
    monkeypatch.setattr(hostinfo, "python_info", lambda: py)
    monkeypatch.setattr(hostinfo, "numpy_module", lambda: probes.get("numpy", NUMPY))
    monkeypatch.setattr(hostinfo, "opencv", lambda root: probes.get("opencv", NO_CV))
    monkeypatch.setattr(
        hostinfo, "picamera2_module", lambda: probes.get("picamera2", Module("picamera2", None, None, "not installed"))
    )
    monkeypatch.setattr(hostinfo, "ros2", lambda root: probes.get("ros2", NO_ROS))
    monkeypatch.setattr(hostinfo, "serial_access", lambda: probes.get("serial", []))
    monkeypatch.setattr(hostinfo, "user_name", lambda: "pi")


def _fixes() -> dict[str, str | None]:
    return {f.name: f.fix for f in doctor.findings(Path("/"))}


def test_a_jetson_venv_from_pyenv_is_told_to_use_the_system_python_for_jetpacks_opencv(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    cv = OpenCv(Module("cv2", None, None, "not installed"), None, JETPACK_CV)
    ros = Ros2(None, Module("rclpy", None, None, "not found"), None, ("humble",))
    _stand_in(monkeypatch, JETSON, PYENV, opencv=cv, ros2=ros)
    fixes = _fixes()
    assert fixes["Python"] == f"this venv cannot see the system's OpenCV, picamera2 and ROS: {doctor.SYSTEM_VENV}"
    assert fixes["OpenCV"] == f"JetPack's OpenCV ({JETPACK_CV}) is the system Python's: {doctor.SYSTEM_VENV}"
    assert fixes["ROS 2"] == "source /opt/ros/humble/setup.bash before running `roverlink ros2`"
    assert fixes["picamera2"] is None  # a Pi camera on a Jetson goes through jetson-csi


def test_a_jetson_without_ros_gets_humble_and_an_old_jetpack_the_container(monkeypatch: pytest.MonkeyPatch) -> None:
    _stand_in(monkeypatch, JETSON, SYSTEM)
    assert "sudo apt install ros-humble-ros-base" in str(_fixes()["ROS 2"])
    _stand_in(monkeypatch, JETSON_NANO, SYSTEM)
    assert "JetPack 4's Ubuntu has no ROS 2 on Python 3.10 or later" in str(_fixes()["ROS 2"])
    assert "install JetPack's OpenCV" in str(_fixes()["OpenCV"])


def test_a_pi_with_a_pip_numpy_over_apts_picamera2_gets_the_one_line_and_apt_for_the_rest(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    picam = Module("picamera2", None, "/usr/lib/python3/dist-packages", ABI)
    _stand_in(monkeypatch, PI, SYSTEM, picamera2=picam)
    fixes = _fixes()
    assert fixes["picamera2"] == ABI
    assert str(fixes["OpenCV"]).startswith("sudo apt install python3-opencv gstreamer1.0-plugins-good")
    assert str(fixes["ROS 2"]).startswith("Raspberry Pi OS has no ROS 2 packages")
    _stand_in(monkeypatch, PI, SYSTEM)
    assert _fixes()["picamera2"] == f"sudo apt install python3-picamera2, then {doctor.SYSTEM_VENV}"


def test_a_wheel_without_gstreamer_in_front_of_the_systems_opencv_is_named(monkeypatch: pytest.MonkeyPatch) -> None:
    wheel = Module("cv2", "4.12.0", "/home/me/rl/.venv/lib/python3.10/site-packages")
    cv = OpenCv(
        wheel, OpenCvBuild("4.12.0", gstreamer=False, ffmpeg=True, v4l2=True), "/usr/lib/python3/dist-packages/cv2"
    )
    _stand_in(monkeypatch, UBUNTU, SYSTEM, opencv=cv)
    found = {f.name: f for f in doctor.findings(Path("/"))}
    assert found["OpenCV"].found.endswith("GStreamer no, V4L2 yes")
    assert str(found["OpenCV"].fix).startswith("pip uninstall opencv-python-headless")
    system = OpenCv(
        Module("cv2", "4.5.4", "/usr/lib/python3/dist-packages"), OpenCvBuild("4.5.4", True, True, True), None
    )
    _stand_in(monkeypatch, UBUNTU, SYSTEM, opencv=system)
    assert _fixes()["OpenCV"] is None


def test_rclpy_built_for_another_python_and_missing_message_packages(monkeypatch: pytest.MonkeyPatch) -> None:
    built = Ros2(
        "humble",
        Module(
            "rclpy", "3.3.15", "/opt/ros/humble/lib/python3.10/site-packages", "built for Python 3.10, this is 3.11"
        ),
        "3.10",
        ("humble",),
    )
    _stand_in(monkeypatch, UBUNTU, PYENV, ros2=built)
    assert "rclpy is built for Python 3.10: make the venv from the system's python3.10" in str(_fixes()["ROS 2"])
    ok = Ros2("humble", Module("rclpy", "3.3.15", "/opt/ros/humble/lib/python3.10/site-packages"), None, ("humble",))
    _stand_in(monkeypatch, UBUNTU, SYSTEM, ros2=ok)
    monkeypatch.setattr(doctor, "missing_modules", lambda: ["diagnostic_msgs"])
    assert _fixes()["ROS 2"] == "sudo apt install ros-humble-diagnostic-msgs"
    monkeypatch.setattr(doctor, "missing_modules", lambda: [])
    assert _fixes()["ROS 2"] is None
    _stand_in(monkeypatch, Machine("ubuntu", "24.04", "Ubuntu 24.04 LTS", None, None), SYSTEM)
    assert "sudo apt install ros-jazzy-ros-base" in str(_fixes()["ROS 2"])


def test_serial_ports_say_who_may_open_them_and_how_to_join_dialout(monkeypatch: pytest.MonkeyPatch) -> None:
    def port(device: str) -> PortInfo:
        return PortInfo(device, "Arduino Uno", 0x2341, 0x0043, None, True, "Arduino board")

    ports = [
        PortAccess(port("/dev/ttyACM0"), allowed=False, group="dialout", in_group=False, listed=False),
        PortAccess(port("/dev/ttyACM1"), allowed=False, group="dialout", in_group=False, listed=True),
        PortAccess(port("/dev/ttyACM2"), allowed=True, group="dialout", in_group=True, listed=True),
    ]
    _stand_in(monkeypatch, PI, SYSTEM, serial=ports)
    fixes = _fixes()
    assert fixes["serial /dev/ttyACM0"] == "sudo usermod -aG dialout pi, then log in again"
    assert fixes["serial /dev/ttyACM1"] == "pi is in dialout since the last login: log in again"
    assert fixes["serial /dev/ttyACM2"] is None
    _stand_in(monkeypatch, PI, SYSTEM)
    assert {f.name: f.found for f in doctor.findings(Path("/"))}["serial"].startswith("no serial ports")


def test_roverlink_doctor_names_every_piece_here_one_line_each(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["doctor"]) == 0
    out = capsys.readouterr().out
    names = [line.split()[0] for line in out.splitlines() if line and not line.startswith(" ")]
    assert names[:6] == ["system", "Python", "numpy", "OpenCV", "picamera2", "ROS"]
    assert all(len(line) < 400 for line in out.splitlines())
    assert main(["doctor", "--json"]) == 0
    found = json.loads(capsys.readouterr().out)
    assert {f["name"] for f in found} >= {"system", "Python", "numpy", "OpenCV", "picamera2", "ROS 2"}
