"""Build the ROS 2 message packages that have no PyPI wheel (tf2_msgs) with the rosidl generator wheels.

ROS 2 Jazzy's Python stack installs from PyPI, but `tf2_msgs` (the type of /tf) has no wheel. The
ament/rosidl generator wheels build it from its message definition with CMake and a C compiler in
seconds:

    python -m roverlink.ros2.interfaces --prefix "$VIRTUAL_ENV"   # into this venv: the node publishes /tf
    python -m roverlink.ros2.interfaces --prefix build/ros2       # a cache the tests load (tests/roverlink/ros2)

It needs `pip install 'roverlink[ros2,ros2-build]'`, `cmake` and a C/C++ compiler. A build is
skipped when the prefix already holds one made from the same definitions. A ROS 2 distribution
(`source /opt/ros/jazzy/setup.bash`) has tf2_msgs already: nothing to build there.
"""

from __future__ import annotations

import argparse
import ctypes
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from host_sdk import RoverLinkError


@dataclass(frozen=True, slots=True)
class InterfacePackage:
    name: str
    version: str
    messages: dict[str, str]
    """Message name -> its .msg definition."""
    depends: tuple[str, ...]


TF2_MSGS = InterfacePackage(
    name="tf2_msgs",
    version="0.36.0",
    messages={"TFMessage": "geometry_msgs/TransformStamped[] transforms\n"},
    depends=("geometry_msgs",),
)

_PACKAGE_XML = """<?xml version="1.0"?>
<package format="3">
  <name>{name}</name>
  <version>{version}</version>
  <description>{name} messages, built by roverlink.ros2.interfaces from their definitions.</description>
  <maintainer email="roverlink@example.invalid">RoverLink</maintainer>
  <license>BSD-3-Clause</license>
  <buildtool_depend>ament_cmake</buildtool_depend>
  <buildtool_depend>rosidl_default_generators</buildtool_depend>
{depends}
  <exec_depend>rosidl_default_runtime</exec_depend>
  <member_of_group>rosidl_interface_packages</member_of_group>
  <export><build_type>ament_cmake</build_type></export>
</package>
"""

# The generator wheels' exported CMake targets name the Python include directories of the machine
# that built them (/opt/python/cp311-cp311/...); CMake refuses targets whose include paths do not
# exist. Point them at this interpreter's instead, so nothing outside the build needs to change.
_CMAKE = """cmake_minimum_required(VERSION 3.16)
project({name})
find_package(ament_cmake REQUIRED)
find_package(rosidl_default_generators REQUIRED)
{find_depends}
rosidl_generate_interfaces(${{PROJECT_NAME}} {msg_files} DEPENDENCIES {depends})
get_directory_property(_imported IMPORTED_TARGETS)
foreach(_target IN LISTS _imported)
  get_target_property(_include ${{_target}} INTERFACE_INCLUDE_DIRECTORIES)
  if(_include AND _include MATCHES "/opt/python/")
    set_target_properties(${{_target}} PROPERTIES
      INTERFACE_INCLUDE_DIRECTORIES "${{Python3_INCLUDE_DIRS}};${{Python3_NumPy_INCLUDE_DIRS}}")
  endif()
endforeach()
ament_package()
"""


class InterfaceBuildError(RoverLinkError, RuntimeError):
    """The interface package could not be built; the message says what is missing or what failed."""


def ros_prefixes() -> list[Path]:
    """Where the ROS 2 packages are: AMENT_PREFIX_PATH, and this environment (PyPI wheels install there)."""
    out = [Path(p) for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    if Path(sys.prefix) not in out:
        out.append(Path(sys.prefix))
    return [p for p in out if (p / "share").is_dir()]


def site_packages(prefix: Path) -> Path:
    return prefix / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / "site-packages"


def _fingerprint(package: InterfacePackage) -> str:
    # The interpreter too: the build links against the ROS wheels of one environment.
    inputs = [package.name, package.version, package.messages, package.depends, _CMAKE, sys.executable]
    text = json.dumps(inputs, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _stamp(prefix: Path, package: InterfacePackage) -> Path:
    return prefix / "share" / package.name / "roverlink-build.json"


def is_built(prefix: Path, package: InterfacePackage = TF2_MSGS) -> bool:
    stamp = _stamp(prefix, package)
    if not stamp.is_file():
        return False
    try:
        return bool(json.loads(stamp.read_text()).get("fingerprint") == _fingerprint(package))
    except (OSError, ValueError):
        return False


def write_sources(src: Path, package: InterfacePackage) -> None:
    (src / "msg").mkdir(parents=True, exist_ok=True)
    for name, definition in package.messages.items():
        (src / "msg" / f"{name}.msg").write_text(definition)
    depends = "\n".join(f"  <depend>{d}</depend>" for d in package.depends)
    (src / "package.xml").write_text(_PACKAGE_XML.format(name=package.name, version=package.version, depends=depends))
    (src / "CMakeLists.txt").write_text(
        _CMAKE.format(
            name=package.name,
            find_depends="\n".join(f"find_package({d} REQUIRED)" for d in package.depends),
            msg_files=" ".join(f'"msg/{n}.msg"' for n in package.messages),
            depends=" ".join(package.depends),
        )
    )


def _check_tools(ros: list[Path]) -> None:
    missing = [tool for tool in ("cmake", "cc", "c++") if shutil.which(tool) is None]
    if missing:
        raise InterfaceBuildError(
            f"building ROS interfaces needs {', '.join(missing)}: install them (Debian: apt-get install cmake g++ make)"
        )
    if not any((p / "share" / "rosidl_default_generators").is_dir() for p in ros):
        raise InterfaceBuildError(
            "the rosidl generators are not installed: pip install 'roverlink[ros2,ros2-build]' "
            f"(looked in {', '.join(str(p) for p in ros) or 'no ROS prefix'})"
        )


def build(prefix: Path, package: InterfacePackage = TF2_MSGS, *, force: bool = False, quiet: bool = True) -> bool:
    """Build `package` and install it into `prefix`; False if an identical build is there already."""
    prefix = prefix.resolve()
    if not force and is_built(prefix, package):
        return False
    ros = ros_prefixes()
    _check_tools(ros)
    env = dict(os.environ)
    env["AMENT_PREFIX_PATH"] = os.pathsep.join(str(p) for p in ros)
    cmake_prefix = ";".join(str(p) for p in ros)
    out = subprocess.DEVNULL if quiet else None
    with tempfile.TemporaryDirectory(prefix=f"roverlink-{package.name}-") as tmp:
        src, work = Path(tmp) / "src", Path(tmp) / "build"
        write_sources(src, package)
        steps = [
            [
                "cmake",
                "-S",
                str(src),
                "-B",
                str(work),
                f"-DCMAKE_PREFIX_PATH={cmake_prefix}",
                f"-DCMAKE_INSTALL_PREFIX={prefix}",
                f"-DPython3_EXECUTABLE={sys.executable}",
                "-DBUILD_TESTING=OFF",
                "-DCMAKE_BUILD_TYPE=Release",
            ],
            ["cmake", "--build", str(work), "--parallel", str(min(os.cpu_count() or 1, 4))],
            ["cmake", "--install", str(work)],
        ]
        for step in steps:
            result = subprocess.run(step, env=env, stdout=out, stderr=subprocess.PIPE, text=True, check=False)
            if result.returncode != 0:
                tail = "\n".join(result.stderr.strip().splitlines()[-25:])
                raise InterfaceBuildError(f"{' '.join(step[:3])} failed ({result.returncode}):\n{tail}")
    _stamp(prefix, package).write_text(json.dumps({"fingerprint": _fingerprint(package), "python": sys.executable}))
    return True


def environment(prefix: Path, base: dict[str, str] | None = None) -> dict[str, str]:
    """`base` (default os.environ) with `prefix` added to the paths ROS and Python search."""
    env = dict(os.environ if base is None else base)
    prefix = prefix.resolve()
    for var, path in (
        ("PYTHONPATH", site_packages(prefix)),
        ("LD_LIBRARY_PATH", prefix / "lib"),
        ("AMENT_PREFIX_PATH", prefix),
    ):
        parts = [p for p in env.get(var, "").split(os.pathsep) if p and p != str(path)]
        env[var] = os.pathsep.join([str(path), *parts])
    return env


def activate(prefix: Path) -> None:
    """Make packages built into `prefix` importable in this running process.

    The dynamic loader read LD_LIBRARY_PATH when the process started, so the package's libraries
    are loaded here by path (dependencies first); the environment is updated for the ROS type
    support lookups done later and for child processes."""
    prefix = prefix.resolve()
    os.environ.update(environment(prefix))
    path = str(site_packages(prefix))
    if path not in sys.path:
        sys.path.insert(0, path)
    pending = sorted((prefix / "lib").glob("lib*.so"))
    while pending:
        failed = []
        for lib in pending:
            try:
                ctypes.CDLL(str(lib), mode=ctypes.RTLD_GLOBAL)
            except OSError:
                failed.append(lib)
        if len(failed) == len(pending):
            raise InterfaceBuildError(f"cannot load {', '.join(p.name for p in failed)} from {prefix / 'lib'}")
        pending = failed


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m roverlink.ros2.interfaces", description=__doc__.split("\n\n")[0])
    parser.add_argument("--prefix", type=Path, required=True, help="install prefix (a venv, or a cache folder)")
    parser.add_argument("--force", action="store_true", help="build even if an identical build is installed")
    parser.add_argument("--verbose", action="store_true", help="show CMake's output")
    args = parser.parse_args(argv)
    try:
        built = build(args.prefix, force=args.force, quiet=not args.verbose)
    except InterfaceBuildError as exc:
        print(f"{parser.prog}: {exc}", file=sys.stderr)
        return 1
    where = args.prefix.resolve()
    print(f"tf2_msgs {'built into' if built else 'already built in'} {where}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
