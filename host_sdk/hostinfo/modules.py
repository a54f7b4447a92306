"""The Python modules the host's features rest on: numpy, OpenCV (and what its build can open),
picamera2 and rclpy, each found where this interpreter finds it, without importing ROS."""

from __future__ import annotations

import importlib.util
import os
import re
import sys
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

from host_sdk.extras import NumpyAbiError, import_compiled
from host_sdk.sensors.camera.pipelines import OpenCvBuild, opencv_build
from protocol.numpy_abi import SYSTEM_PREFIX, location


@dataclass(frozen=True, slots=True)
class Module:
    name: str
    version: str | None
    """None: it cannot be used here (`problem` says why)."""
    location: str | None
    problem: str | None = None

    @property
    def from_system(self) -> bool:
        """Installed by the distribution (apt, JetPack), not by pip."""
        return (self.location or "").startswith(SYSTEM_PREFIX)


@dataclass(frozen=True, slots=True)
class OpenCv:
    module: Module
    build: OpenCvBuild | None
    system_copy: str | None
    """A distribution's cv2 on disk (for the system's Python) when this is not it: a wheel hides it,
    or this interpreter does not see it."""


@dataclass(frozen=True, slots=True)
class Ros2:
    distro: str | None
    """ROS_DISTRO, else the distribution rclpy comes from (its /opt/ros/<distro> or ros-<distro>-rclpy wheel)."""
    rclpy: Module
    built_for: str | None
    """The Python rclpy's C extension was built for ("3.10"), when it is not this one's."""
    installed: tuple[str, ...]
    """The ROS 2 distributions under /opt/ros."""


def _imported(name: str) -> tuple[Module, ModuleType | None]:
    try:
        module = import_compiled(name)
    except NumpyAbiError as exc:
        return Module(name, None, location(exc.module), str(exc)), None
    except ImportError as exc:
        return Module(name, None, None, "not installed" if exc.name == name else f"cannot be imported ({exc})"), None
    version = getattr(module, "__version__", None) or _version(name)
    return Module(name, str(version) if version else "?", location(name)), module


def numpy_module() -> Module:
    return _imported("numpy")[0]


def picamera2_module() -> Module:
    return _imported("picamera2")[0]


def opencv(root: Path = Path("/")) -> OpenCv:
    found, cv2 = _imported("cv2")
    build = opencv_build(cv2) if cv2 is not None else None
    copies = sorted(str(p) for p in (root / "usr" / "lib").glob("python3*/dist-packages/cv2*"))
    system = copies[0] if copies and not found.from_system else None
    return OpenCv(found, build, system)


def _version(dist: str) -> str | None:
    import importlib.metadata  # noqa: PLC0415 (reading installed metadata: only when asked)

    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return None


def ros2(root: Path = Path("/")) -> Ros2:
    """rclpy found but not imported (ROS's import has side effects, and a mismatched build crashes)."""
    installed = tuple(sorted(p.name for p in (root / "opt" / "ros").glob("*") if (p / "setup.bash").exists()))
    try:
        spec = importlib.util.find_spec("rclpy")
    except (ImportError, ValueError):
        spec = None
    distro = os.environ.get("ROS_DISTRO") or None
    if spec is None or not spec.origin:
        return Ros2(distro, Module("rclpy", None, None, "not found"), None, installed)
    folder = Path(spec.origin).parent
    where = re.search(r"/opt/ros/(\w+)/", str(folder))
    wheel = next(iter(folder.parent.glob("ros_*_rclpy-*.dist-info")), None)
    if distro is None and where:
        distro = where.group(1)
    elif distro is None and wheel is not None:
        distro = wheel.name.split("_")[1]
    # The C extension's file name says which Python it was built for (_rclpy_pybind11.cpython-310-...).
    found = (re.search(r"cpython-(\d)(\d+)", so.name) for so in folder.glob("_rclpy_pybind11*.so"))
    tags = {f"{m.group(1)}.{m.group(2)}" for m in found if m}
    here = f"{sys.version_info.major}.{sys.version_info.minor}"
    built_for = None if not tags or here in tags else sorted(tags)[0]
    module = Module("rclpy", _version("rclpy") or "?", str(folder.parent))
    if built_for is not None:
        module = Module("rclpy", module.version, module.location, f"built for Python {built_for}, this is {here}")
    return Ros2(distro, module, built_for, installed)
