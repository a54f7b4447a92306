"""host_sdk.hostinfo: the machine read from /etc and /proc (a fake root here), this Python, the
modules as this interpreter finds them, rclpy's build found without importing it, and the serial
ports' access."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy
import pytest

from host_sdk import hostinfo
from host_sdk.ports import PortInfo


def _root(tmp_path: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return tmp_path


UBUNTU_2204 = 'PRETTY_NAME="Ubuntu 22.04.4 LTS"\nNAME="Ubuntu"\nVERSION_ID="22.04"\nID=ubuntu\n'


@pytest.mark.parametrize(
    ("files", "kind", "board", "jetpack"),
    [
        (
            {
                "etc/os-release": UBUNTU_2204,
                "proc/device-tree/model": "NVIDIA Jetson Orin Nano Developer Kit\0",
                "etc/nv_tegra_release": "# R36 (release), REVISION: 3.0, GCID: 36191598, BOARD: generic, EABI: aarch64\n",
            },
            "jetson",
            "NVIDIA Jetson Orin Nano Developer Kit",
            "6",
        ),
        (
            {
                "etc/os-release": 'PRETTY_NAME="Ubuntu 18.04.6 LTS"\nID=ubuntu\nVERSION_ID="18.04"\n',
                "etc/nv_tegra_release": "# R32 (release), REVISION: 7.4, GCID: 33514132, BOARD: t210ref\n",
            },
            "jetson",
            None,
            "4",
        ),
        (
            {
                "etc/os-release": 'PRETTY_NAME="Debian GNU/Linux 12 (bookworm)"\nID=debian\nVERSION_ID="12"\n',
                "proc/device-tree/model": "Raspberry Pi 5 Model B Rev 1.0\0",
            },
            "raspberry-pi",
            "Raspberry Pi 5 Model B Rev 1.0",
            None,
        ),
        ({"etc/os-release": UBUNTU_2204}, "ubuntu", None, None),
        ({}, "other", None, None),
    ],
)
def test_the_machine_is_read_from_os_release_the_device_tree_and_l4t(
    tmp_path: Path, files: dict[str, str], kind: str, board: str | None, jetpack: str | None
) -> None:
    m = hostinfo.machine(_root(tmp_path, files))
    assert (m.kind, m.board, m.jetpack) == (kind, board, jetpack)
    if "nv_tegra_release" in str(files):
        assert m.l4t in ("36.3.0", "32.7.4")


def test_this_python_is_described_as_it_runs() -> None:
    py = hostinfo.python_info()
    assert py.version[:2] == sys.version_info[:2] and py.executable == sys.executable
    assert py.venv == (sys.prefix != sys.base_prefix)
    assert py.text.startswith(f"{sys.version_info.major}.{sys.version_info.minor}.")


def test_modules_are_found_where_this_interpreter_finds_them() -> None:
    found = hostinfo.numpy_module()
    assert found.version == numpy.__version__ and found.problem is None
    assert found.location == str(Path(numpy.__file__).parent.parent)
    picam = hostinfo.picamera2_module()
    assert picam.problem is None or picam.version is None


def test_rclpy_built_for_another_python_is_found_without_importing_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    site = tmp_path / "opt" / "ros" / "humble" / "lib" / "python3.9" / "site-packages"
    (site / "rclpy").mkdir(parents=True)
    (site / "rclpy" / "__init__.py").write_text("raise RuntimeError('imported')\n", encoding="utf-8")
    (site / "rclpy" / "_rclpy_pybind11.cpython-39-aarch64-linux-gnu.so").write_bytes(b"")
    (tmp_path / "opt" / "ros" / "humble" / "setup.bash").write_text("", encoding="utf-8")
    monkeypatch.syspath_prepend(str(site))
    monkeypatch.delitem(sys.modules, "rclpy", raising=False)
    monkeypatch.delenv("ROS_DISTRO", raising=False)
    ros = hostinfo.ros2(tmp_path)
    assert ros.distro == "humble" and ros.installed == ("humble",)
    assert (
        ros.built_for == "3.9"
        and ros.rclpy.problem == f"built for Python 3.9, this is {sys.version_info[0]}.{sys.version_info[1]}"
    )
    assert "rclpy" not in sys.modules


def test_no_rclpy_and_the_distributions_under_opt_ros(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "rclpy", None)  # find_spec then raises: not importable here
    root = _root(tmp_path, {"opt/ros/jazzy/setup.bash": "", "opt/ros/humble/setup.bash": ""})
    ros = hostinfo.ros2(root)
    assert ros.rclpy.location is None and ros.installed == ("humble", "jazzy")


def test_a_port_says_whether_this_user_may_open_it_and_its_group(tmp_path: Path) -> None:
    node = tmp_path / "ttyACM0"
    node.write_bytes(b"")
    port = PortInfo(str(node), "Arduino Uno", 0x2341, 0x0043, None, True, "Arduino board")
    access = hostinfo.port_access(port)
    assert access.allowed and access.group is not None and access.in_group
    gone = hostinfo.port_access(PortInfo(str(tmp_path / "missing"), "", None, None, None, False, ""))
    assert not gone.allowed and gone.group is None
