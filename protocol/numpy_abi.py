"""A compiled module that cannot load with the numpy installed, said in one line with the fix.

The distributions' picamera2, simplejpeg and OpenCV (Raspberry Pi OS, Debian, Ubuntu, JetPack)
are built against their own numpy (1.24 on Debian 12 and Raspberry Pi OS Bookworm). A numpy from
pip in front of it (numpy 2, which the opencv-python-headless wheel requires) breaks them, and the
errors name neither the module nor numpy: "numpy.dtype size changed, may indicate binary
incompatibility", "numpy.core.multiarray failed to import", "_ARRAY_API not found". The other way
round, a wheel built for numpy 2 fails the same way over the distribution's numpy 1.
"""

from __future__ import annotations

import importlib.util
import sys
import traceback
from pathlib import Path

SIGNATURES = (
    "numpy.dtype size changed",
    "numpy.ufunc size changed",
    "multiarray failed to import",
    "_ARRAY_API not found",
    "compiled against ABI version",
    "compiled against API version",
    "compiled using NumPy 1.x cannot be run",
)
SYSTEM_PREFIX = "/usr/lib/python3"
"""Where the distributions' Python packages are (apt's dist-packages, JetPack's OpenCV too)."""


def is_numpy_abi_break(exc: BaseException) -> bool:
    """True when `exc` (or what caused it) is numpy refusing a module built for another numpy."""
    seen: BaseException | None = exc
    while seen is not None:
        if any(s in str(seen) for s in SIGNATURES):
            return True
        seen = seen.__cause__ or seen.__context__
    return False


def _package_of(filename: str) -> str | None:
    """The top-level package a file in a site-packages or dist-packages folder belongs to."""
    parts = Path(filename).parts
    for i, part in enumerate(parts[:-1]):
        if part in ("site-packages", "dist-packages"):
            return parts[i + 1].removesuffix(".py")
    return None


def failing_module(exc: BaseException, module: str) -> str:
    """The compiled module that failed: the innermost installed package in the traceback other
    than numpy (simplejpeg when picamera2 is imported), else `module`'s top level."""
    found = module.split(".", maxsplit=1)[0]
    for frame in traceback.extract_tb(exc.__traceback__):
        package = _package_of(frame.filename)
        if package and package != "numpy":
            found = package
    return found


def location(module: str) -> str:
    """The folder `module` is installed in ("?" when it cannot be found)."""
    loaded = sys.modules.get(module)
    origin = getattr(loaded, "__file__", None)
    if origin is None:
        try:
            spec = importlib.util.find_spec(module)
        except (ImportError, ValueError):
            spec = None
        origin = spec.origin if spec is not None else None
    if not origin:
        return "?"
    path = Path(origin).parent
    return str(path.parent if path.name == module else path)


def _from_system(folder: str) -> bool:
    return folder.startswith(SYSTEM_PREFIX)


def _distributions(module: str) -> list[str]:
    import importlib.metadata  # noqa: PLC0415 (only once something failed: not on every import)

    return sorted(set(importlib.metadata.packages_distributions().get(module, [])))


def numpy_version() -> str:
    numpy = sys.modules.get("numpy")
    return str(getattr(numpy, "__version__", "?"))


def fix(culprit: str) -> str:
    """What to do, from where the failing module and numpy each come from."""
    culprit_dir, numpy_dir = location(culprit), location("numpy")
    wheels = [d for d in _distributions("cv2") if not _from_system(location("cv2"))]
    if _from_system(culprit_dir) and not _from_system(numpy_dir):
        remove = " ".join(["numpy", *wheels])
        return (
            f"keep the system's numpy, which {culprit} is built for: `pip uninstall {remove}` in this environment "
            "(install RoverLink without the vision extra where the system has OpenCV: "
            "docs/sensors.md#one-route-per-platform)"
        )
    dists = " ".join(_distributions(culprit)) or culprit
    if _from_system(numpy_dir):
        return (
            f"`pip uninstall {dists}` and use the system's package (e.g. sudo apt install python3-opencv), or "
            f"install {dists} in a venv without --system-site-packages, which gets numpy from pip"
        )
    return f"reinstall the two for each other: `pip install --force-reinstall {dists} numpy`"


def describe(module: str, exc: BaseException) -> str:
    """The one line: the module, what failed in it, the numpy found, the fix."""
    culprit = failing_module(exc, module)
    through = (
        f" (its {culprit}, {location(culprit)})"
        if culprit != module.split(".", maxsplit=1)[0]
        else f" ({location(culprit)})"
    )
    first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    first = first if len(first) <= 120 else first[:117] + "..."
    return (
        f"{module}{through} cannot be loaded with numpy {numpy_version()} ({location('numpy')}): it was built "
        f"against another numpy ({first}); {fix(culprit)}"
    )
