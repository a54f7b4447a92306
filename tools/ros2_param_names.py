"""Collect the parameter names ROS 2 Jazzy's Nav2 and SLAM Toolbox packages declare, from their sources.

    python tools/ros2_param_names.py NAV2_GIT_DIR SLAM_GIT_DIR > tests/roverlink/ros2/jazzy_param_names.toml

Both arguments are git directories (clones or mirrors of ros-navigation/navigation2 and
SteveMacenski/slam_toolbox). The names are the string literals inside the packages' parameter
calls (declare_parameter, declare_parameter_if_not_declared, declareParameter, get_parameter,
getParam); the test of examples/ros2 checks every key of the generated SLAM Toolbox and Nav2
files against them. Only names are taken, nothing else of the sources.
"""

from __future__ import annotations

import re
import subprocess
import sys

NAV2_REF = "jazzy"
SLAM_REF = "ros2"  # SLAM Toolbox's Jazzy releases are made from its ros2 branch
NAV2_PACKAGES = (
    "nav2_behavior_tree",
    "nav2_behaviors",
    "nav2_bt_navigator",
    "nav2_collision_monitor",
    "nav2_controller",
    "nav2_costmap_2d",
    "nav2_docking",
    "nav2_dwb_controller",
    "nav2_mppi_controller",
    "nav2_navfn_planner",
    "nav2_planner",
    "nav2_regulated_pure_pursuit_controller",
    "nav2_route",
    "nav2_smac_planner",
    "nav2_smoother",
    "nav2_util",
    "nav2_velocity_smoother",
    "nav2_waypoint_follower",
)
_CALL = re.compile(
    r"\b(declare_parameter_if_not_declared|declare_parameter|declareParameter|get_parameter_or|"
    r"get_parameter|getParam)\s*\("
)
_LITERAL = re.compile(r'"\.?((?:[A-Za-z_][A-Za-z0-9_]*\.)*[A-Za-z_][A-Za-z0-9_]*)"')


def _git(repo: str, *args: str) -> str:
    return subprocess.run(["git", "--git-dir", repo, *args], check=True, capture_output=True, text=True).stdout


def _call_args(text: str, start: int) -> str:
    depth, i = 1, start
    while i < len(text) and depth:
        depth += {"(": 1, ")": -1}.get(text[i], 0)
        i += 1
    return text[start:i]


def names_in(repo: str, ref: str, folder: str) -> list[str]:
    """Every parameter name the C++ sources under `folder` (not its tests) declare or read."""
    files = _git(repo, "ls-tree", "-r", "--name-only", ref, "--", folder).split()
    found: set[str] = set()
    for path in files:
        if not path.endswith((".cpp", ".hpp", ".h")) or "/test" in path:
            continue
        text = _git(repo, "show", f"{ref}:{path}")
        for call in _CALL.finditer(text):
            # "controller.k_phi": the parameter is the last part (the others are namespaces)
            found.update(lit.rsplit(".", 1)[-1] for lit in _LITERAL.findall(_call_args(text, call.end())))
    return sorted(found)


def launch_arguments(repo: str, ref: str, path: str) -> list[str]:
    """The arguments a launch file declares."""
    text = _git(repo, "show", f"{ref}:{path}")
    return sorted(set(re.findall(r"DeclareLaunchArgument\(\s*['\"]([A-Za-z_]+)['\"]", text)))


def _section(name: str, source: str, names: list[str]) -> str:
    lines = [f"[{name}]", f'source = "{source}"', "names = ["]
    lines += [f'    "{n}",' for n in names]
    return "\n".join([*lines, "]", ""])


def main(nav2: str, slam: str) -> None:
    nav2_commit = _git(nav2, "rev-parse", NAV2_REF).strip()
    slam_commit = _git(slam, "rev-parse", SLAM_REF).strip()
    nav2_version = re.search(r"<version>(.+)</version>", _git(nav2, "show", f"{NAV2_REF}:nav2_bringup/package.xml"))
    slam_version = re.search(r"<version>(.+)</version>", _git(slam, "show", f"{SLAM_REF}:package.xml"))
    print("# Parameter names that ROS 2 Jazzy's Nav2 and SLAM Toolbox declare, per package, from the")
    print("# packages' sources (the string literals of their parameter calls): written by")
    print("# tools/ros2_param_names.py; every key of examples/ros2/*/nav2.yaml and slam_toolbox.yaml must be here.")
    print(f"# navigation2: branch {NAV2_REF} at {nav2_commit} (nav2_bringup {nav2_version and nav2_version[1]})")
    print(f"# slam_toolbox: branch {SLAM_REF} at {slam_commit} (package.xml {slam_version and slam_version[1]})")
    print()
    for package in NAV2_PACKAGES:
        source = f"navigation2 {NAV2_REF} {nav2_commit[:10]}: {package}/**/*.cpp, *.hpp"
        print(_section(package, source, names_in(nav2, NAV2_REF, package)))
    slam_dirs = ("src", "solvers", "include", "lib/karto_sdk")
    names = sorted({n for d in slam_dirs for n in names_in(slam, SLAM_REF, d)})
    print(_section("slam_toolbox", f"slam_toolbox {SLAM_REF} {slam_commit[:10]}: src, solvers, include", names))
    for repo, label, ref, commit, path in (
        (nav2, "navigation2", NAV2_REF, nav2_commit, "nav2_bringup/launch/navigation_launch.py"),
        (slam, "slam_toolbox", SLAM_REF, slam_commit, "launch/online_async_launch.py"),
    ):
        source = f"{label} {ref} {commit[:10]}: {path} (its DeclareLaunchArgument names)"
        print(
            _section(f"launch.{path.rsplit('/', 1)[-1].removesuffix('.py')}", source, launch_arguments(repo, ref, path))
        )


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
