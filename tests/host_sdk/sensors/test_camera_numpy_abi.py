"""A numpy that does not match the compiled camera modules (apt's picamera2, simplejpeg or
OpenCV under a pip numpy 2, or a wheel built for numpy 2 over the system's numpy 1) is reported
in one line naming the module, the numpy found and the fix, not as numpy's own errors. The
modules here are stand-ins that fail as the real ones do; scripts/test_system_opencv.sh breaks
Debian's real OpenCV with a pip numpy too (test_camera_system_opencv.py)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy
import pytest

from host_sdk.extras import MissingDependencyError, NumpyAbiError, require
from host_sdk.sensors.camera.listing import list_cameras
from host_sdk.sensors.camera.picam import import_picamera2
from protocol import numpy_abi
from roverlink.cli import main

DTYPE_SIZE = (
    "numpy.dtype size changed, may indicate binary incompatibility. Expected 96 from C header, got 88 from PyObject"
)
BANNER = (
    "\nA module that was compiled using NumPy 1.x cannot be run in\nNumPy 2.2.6 as it may crash. To support both 1.x "
    "and 2.x\nversions of NumPy, modules must be compiled with NumPy 2.0.\n"
)


def _package(folder: Path, name: str, code: str) -> None:
    (folder / name).mkdir(parents=True)
    (folder / name / "__init__.py").write_text(code, encoding="utf-8")


@pytest.fixture
def system(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A stand-in for /usr/lib/python3/dist-packages holding apt's picamera2 and simplejpeg, in
    front of the path; this venv's numpy (from pip) is the one imported."""
    folder = tmp_path / "usr-lib-python3" / "dist-packages"
    _package(folder, "simplejpeg", f"import numpy\nraise ValueError({DTYPE_SIZE!r})\n")
    _package(folder, "picamera2", "import simplejpeg\n")
    monkeypatch.setattr(numpy_abi, "SYSTEM_PREFIX", str(tmp_path / "usr-lib-python3"))
    for name in ("picamera2", "simplejpeg"):
        monkeypatch.delitem(sys.modules, name, raising=False)
    monkeypatch.syspath_prepend(str(folder))
    return folder


def test_picamera2_whose_simplejpeg_numpy_refuses_is_named_with_numpy_and_the_fix(system: Path) -> None:
    with pytest.raises(NumpyAbiError) as err:
        import_picamera2("picamera2")
    text = str(err.value)
    assert "\n" not in text
    assert text.startswith(f"picamera2 (its simplejpeg, {system}) cannot be loaded with numpy {numpy.__version__}")
    assert "numpy.dtype size changed" in text
    assert "keep the system's numpy, which simplejpeg is built for: `pip uninstall numpy" in text
    assert isinstance(err.value, MissingDependencyError) and isinstance(err.value, ImportError)


def test_a_module_numpy_2_refuses_prints_no_banner_and_says_it_in_one_line(
    system: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    code = f"import sys\nsys.stderr.write({BANNER!r})\nraise ImportError('numpy.core.multiarray failed to import')\n"
    _package(system, "cv2", code)
    monkeypatch.delitem(sys.modules, "cv2", raising=False)
    with pytest.raises(NumpyAbiError, match=r"^cv2 \(.*\) cannot be loaded with numpy .*multiarray failed to import"):
        require("cv2", "vision", "the camera")
    assert capsys.readouterr().err == ""


def test_roverlink_cameras_shows_each_broken_module_on_one_line(
    system: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    _package(system, "cv2", "raise ImportError('numpy.core.multiarray failed to import')\n")
    monkeypatch.delitem(sys.modules, "cv2", raising=False)
    assert main(["cameras", "--root", str(tmp_path)]) == 0
    out = capsys.readouterr().out.splitlines()
    opencv = next(line for line in out if line.startswith("OpenCV:"))
    picam = next(line for line in out if line.startswith("picamera2:"))
    assert "cv2 (" in opencv and f"numpy {numpy.__version__}" in opencv and "pip uninstall numpy" in opencv
    assert "picamera2 (its simplejpeg" in picam and "pip uninstall numpy" in picam
    listing = list_cameras(tmp_path)
    assert listing.opencv is None and listing.opencv_missing == opencv.removeprefix("OpenCV: ")


def test_a_wheel_over_the_systems_numpy_is_told_to_go(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A pip module built for numpy 2 while numpy comes from the system: remove the wheel."""
    folder = tmp_path / "venv" / "site-packages"
    _package(folder, "fastjpeg", f"raise ValueError({DTYPE_SIZE!r})\n")
    monkeypatch.syspath_prepend(str(folder))
    monkeypatch.setattr(
        numpy_abi, "location", lambda m: "/usr/lib/python3/dist-packages" if m == "numpy" else str(folder)
    )
    with pytest.raises(NumpyAbiError, match=r"`pip uninstall fastjpeg` and use the system's package"):
        require("fastjpeg", "vision", "the camera")


def test_other_import_failures_are_left_as_they_were(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _package(tmp_path, "brokenmod", "raise ValueError('something else')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    with pytest.raises(ValueError, match="something else"):
        require("brokenmod", "vision", "the camera")
    with pytest.raises(MissingDependencyError, match="pip install 'roverlink\\[vision\\]'"):
        require("no_such_module_here", "vision", "the camera")


@pytest.mark.parametrize(
    "message",
    [
        DTYPE_SIZE,
        "numpy.core.multiarray failed to import",
        "numpy._core.multiarray failed to import",
        "_ARRAY_API not found",
        "module compiled against ABI version 0x1000009 but this version of numpy is 0x2000000",
    ],
)
def test_each_way_numpy_refuses_a_module_is_recognised(message: str) -> None:
    assert numpy_abi.is_numpy_abi_break(ImportError(message))
    try:
        try:
            raise AttributeError(message)
        except AttributeError as inner:
            raise ImportError("cv2 failed") from inner
    except ImportError as outer:
        assert numpy_abi.is_numpy_abi_break(outer)
    assert not numpy_abi.is_numpy_abi_break(ImportError("No module named 'cv2'"))
