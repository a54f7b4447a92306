"""examples/ros2/bringup.launch.py and the ros2/roverlink_ros package, without ROS: `launch`,
`launch_ros` and `ament_index_python` are stand-ins that record what the launch file asks for.

Checked: the packages, executables and launch files it names are the right ones (the node's is
the wrapper package's console script; the included launch files and their arguments are Jazzy's,
jazzy_param_names.toml), every file it passes exists, the node gets its robot's parameters file,
and the wrapper package installs all of it with a real setuptools.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import types
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import yaml

from protocol.robotfile import REFERENCES
from protocol.toml import tomllib

ROOT = Path(__file__).resolve().parents[3]
LAUNCH = ROOT / "examples" / "ros2" / "bringup.launch.py"
PACKAGE = ROOT / "ros2" / "roverlink_ros"
KNOWN = tomllib.loads((Path(__file__).with_name("jazzy_param_names.toml")).read_text(encoding="utf-8"))
SHARE = Path("/opt/ros/jazzy/share")
REAL_RUN = subprocess.run
"""subprocess.run before a test replaces it for the launch file."""


class Action:
    """A stand-in launch action or substitution: keeps its arguments."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self.args, self.kwargs = args, kwargs


class LaunchConfiguration(Action):
    def perform(self, context: dict[str, str]) -> str:
        return context[self.args[0]]


def _fake_modules() -> dict[str, types.ModuleType]:
    def module(name: str, **attrs: Any) -> types.ModuleType:
        mod = types.ModuleType(name)
        mod.__dict__.update(attrs)
        return mod

    names = ("DeclareLaunchArgument", "IncludeLaunchDescription", "OpaqueFunction", "ExecuteProcess")
    return {
        "launch": module("launch", LaunchDescription=Action, LaunchContext=dict),
        "launch.actions": module("launch.actions", **{n: type(n, (Action,), {}) for n in names}),
        "launch.launch_description_sources": module(
            "launch.launch_description_sources", PythonLaunchDescriptionSource=type("Source", (Action,), {})
        ),
        "launch.substitutions": module("launch.substitutions", LaunchConfiguration=LaunchConfiguration),
        "launch_ros": module("launch_ros"),
        "launch_ros.actions": module("launch_ros.actions", Node=type("Node", (Action,), {})),
        "ament_index_python": module("ament_index_python"),
        "ament_index_python.packages": module(
            "ament_index_python.packages", get_package_share_directory=lambda pkg: str(SHARE / pkg)
        ),
    }


@pytest.fixture
def launch_file(monkeypatch: pytest.MonkeyPatch) -> Iterator[types.ModuleType]:
    for name, mod in _fake_modules().items():
        monkeypatch.setitem(sys.modules, name, mod)
    spec = importlib.util.spec_from_file_location("bringup_launch", LAUNCH)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    yield mod


def _run_roverlink(calls: list[list[str]]) -> Any:
    """subprocess.run for the launch file's `roverlink ...` calls: `robot new` and `ros2-config` for
    real (this checkout's), `robot urdf` (not this test's subject) writes a stand-in URDF."""

    def run(cmd: list[str], check: bool = False) -> subprocess.CompletedProcess[bytes]:
        calls.append(cmd)
        assert cmd[0] == "roverlink" and check
        if cmd[1:3] == ["robot", "urdf"]:
            assert Path(cmd[3]).is_file()
            Path(cmd[cmd.index("-o") + 1]).write_text("<robot name='r'/>", encoding="utf-8")
            return subprocess.CompletedProcess(cmd, 0)
        env = {**os.environ, "PYTHONPATH": str(ROOT)}
        return REAL_RUN([sys.executable, "-m", "roverlink", *cmd[1:]], check=True, env=env, capture_output=True)

    return run


def _setup(launch_file: types.ModuleType, context: dict[str, str], monkeypatch: pytest.MonkeyPatch) -> Any:
    description = launch_file.generate_launch_description()
    declared = {a.args[0]: a.kwargs.get("default_value") for a in description.args[0] if a.args}
    opaque = [a for a in description.args[0] if type(a).__name__ == "OpaqueFunction"]
    assert len(opaque) == 1 and set(context) <= set(declared)
    calls: list[list[str]] = []
    monkeypatch.setattr(launch_file.subprocess, "run", _run_roverlink(calls))
    actions = opaque[0].kwargs["function"]({**declared, **context})
    return actions, calls


def _console_scripts() -> dict[str, str]:
    text = (PACKAGE / "setup.py").read_text(encoding="utf-8")
    entry = text.split('"console_scripts": [')[1].split("]")[0]
    return dict(item.strip(' "').split(" = ") for item in entry.split(","))


@pytest.mark.parametrize("robot", REFERENCES)
def test_a_reference_robot_starts_the_node_urdf_slam_and_nav2(
    launch_file: types.ModuleType, robot: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    actions, calls = _setup(launch_file, {"robot": robot, "url": "/dev/ttyACM1"}, monkeypatch)
    nodes = [a for a in actions if type(a).__name__ == "Node"]
    assert {(n.kwargs["package"], n.kwargs["executable"]) for n in nodes} == {
        ("roverlink_ros", "roverlink"),
        ("robot_state_publisher", "robot_state_publisher"),
    }
    node = next(n for n in nodes if n.kwargs["package"] == "roverlink_ros")
    assert node.kwargs["executable"] in _console_scripts() and node.kwargs["name"] == "roverlink"
    params_file, overrides = node.kwargs["parameters"]
    assert Path(params_file) == ROOT / "examples" / "ros2" / robot / "roverlink.yaml"
    assert yaml.safe_load(Path(params_file).read_text())["/**/roverlink"]["ros__parameters"]["profile"] == robot
    assert overrides["publish_static_tf"] is False and overrides["url"].args == ("url",)
    rsp = next(n for n in nodes if n.kwargs["package"] == "robot_state_publisher")
    assert rsp.kwargs["parameters"][0]["robot_description"] == "<robot name='r'/>"
    urdf_call = next(c for c in calls if c[1:3] == ["robot", "urdf"])
    assert Path(urdf_call[3]).name == f"{robot}.toml"
    includes = {Path(a.args[0].args[0]): dict(a.kwargs["launch_arguments"]) for a in actions if a not in nodes}
    slam = includes[SHARE / "slam_toolbox" / "launch" / "online_async_launch.py"]
    nav2 = includes[SHARE / "nav2_bringup" / "launch" / "navigation_launch.py"]
    assert set(slam) <= set(KNOWN["launch"]["online_async_launch"]["names"])
    assert set(nav2) <= set(KNOWN["launch"]["navigation_launch"]["names"])
    # online_async_launch.py's use_sim_time defaults to true: a real robot must say false.
    assert slam["use_sim_time"].args == ("use_sim_time",)
    assert Path(slam["slam_params_file"]) == ROOT / "examples" / "ros2" / robot / "slam_toolbox.yaml"
    assert Path(nav2["params_file"]) == ROOT / "examples" / "ros2" / robot / "nav2.yaml"


def test_a_robot_file_gets_its_parameters_written_at_launch(
    launch_file: types.ModuleType, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    mine = tmp_path / "mine.toml"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    cmd = [sys.executable, "-m", "roverlink", "robot", "new", str(mine), "--from", "picar"]
    subprocess.run(cmd, check=True, env=env, capture_output=True)
    actions, calls = _setup(launch_file, {"robot": str(mine)}, monkeypatch)
    config = next(c for c in calls if c[1:3] == ["robot", "ros2-config"])
    assert config[3] == str(mine)
    node = next(a for a in actions if a.kwargs.get("package") == "roverlink_ros")
    params = yaml.safe_load(Path(node.kwargs["parameters"][0]).read_text())["/**/roverlink"]["ros__parameters"]
    assert params["robot_file"] == str(mine)


def test_the_package_is_format_3_and_depends_on_what_the_launch_file_uses() -> None:
    root = ET.parse(PACKAGE / "package.xml").getroot()
    assert root.get("format") == "3" and root.findtext("name") == "roverlink_ros"
    assert root.findtext("export/build_type") == "ament_python"
    depends = {e.text for e in root.iter("exec_depend")}
    launch_text = LAUNCH.read_text(encoding="utf-8")
    used = {"launch", "launch_ros", "ament_index_python", "robot_state_publisher", "slam_toolbox", "nav2_bringup"}
    assert all(f'"{pkg}"' in launch_text or f"from {pkg}" in launch_text for pkg in used)
    from roverlink.ros2 import REQUIRED_MODULES

    assert used | set(REQUIRED_MODULES) | {"tf2_msgs"} <= depends
    assert (PACKAGE / "resource" / "roverlink_ros").is_file()


def test_the_package_installs_the_executable_launch_and_config_files(tmp_path: Path) -> None:
    prefix = tmp_path / "install"
    cmd = [sys.executable, str(PACKAGE / "setup.py"), "-q", "egg_info", "--egg-base", str(tmp_path)]
    cmd += ["build", "--build-base", str(tmp_path / "build"), "install", "--prefix", str(prefix)]
    cmd += ["--single-version-externally-managed", "--record", str(tmp_path / "record.txt")]
    subprocess.run(cmd, check=True, capture_output=True, cwd=tmp_path)
    share = prefix / "share" / "roverlink_ros"
    assert (prefix / "share" / "ament_index" / "resource_index" / "packages" / "roverlink_ros").is_file()
    assert (share / "package.xml").is_file() and (share / "launch" / "bringup.launch.py").is_file()
    for robot in REFERENCES:
        assert sorted(p.name for p in (share / "config" / robot).iterdir()) == sorted(
            ["roverlink.yaml", "slam_toolbox.yaml", "nav2.yaml"]
        )
    script = prefix / "lib" / "roverlink_ros" / "roverlink"
    # The first python3 on PATH (the RoverLink venv's), not the one colcon ran.
    assert script.read_text().splitlines()[0] == "#!/usr/bin/env python3"
    site = next(prefix.glob("lib/python*/site-packages"))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)])}
    shown = subprocess.run(
        [sys.executable, str(script), "--help"], check=False, env=env, capture_output=True, text=True
    )
    assert shown.returncode == 0 and "roverlink ros2" in shown.stdout
    assert _console_scripts() == {"roverlink": "roverlink.commands.ros2:main"}
