"""Python 3.10 is the oldest Python supported, and stays so: requires-python, ruff's target and
mypy's version agree, and the checks really apply them (mypy with the project's settings refuses
a 3.11 standard-library API, ruff refuses 3.11 syntax). scripts/test_pythons.sh runs the core
packages' tests on 3.10 and 3.13."""

from __future__ import annotations

import importlib.util
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from protocol.toml import tomllib

ROOT = Path(__file__).resolve().parents[2]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
NEWER_API = """
import asyncio
import tomllib
from typing import Self


class Box:
    def same(self) -> Self:
        return self


async def wait() -> None:
    async with asyncio.timeout(1.0):
        await asyncio.sleep(0)


print(tomllib.loads("a = 1"), Box().same())
"""


def test_requires_python_ruff_and_mypy_name_the_same_oldest_python() -> None:
    oldest = re.fullmatch(r">=(\d+)\.(\d+)", PYPROJECT["project"]["requires-python"])
    assert oldest is not None and oldest.groups() == ("3", "10")
    assert PYPROJECT["tool"]["ruff"]["target-version"] == "py310"
    assert PYPROJECT["tool"]["mypy"]["python_version"] == "3.10"
    script = (ROOT / "scripts" / "test_pythons.sh").read_text(encoding="utf-8")
    assert "versions=(3.10 3.13)" in script


def test_tomli_is_a_dependency_exactly_where_tomllib_is_missing() -> None:
    deps = PYPROJECT["project"]["dependencies"]
    assert "tomli>=1.1; python_version < '3.11'" in deps
    from protocol.toml import tomllib as reader

    assert reader.__name__ == ("tomllib" if sys.version_info >= (3, 11) else "tomli")


def test_mypy_with_the_projects_settings_refuses_what_python_3_10_lacks(tmp_path: Path) -> None:
    if importlib.util.find_spec("mypy") is None:
        pytest.skip("mypy is not installed (the dev extra)")
    probe = tmp_path / "probe.py"
    probe.write_text(NEWER_API, encoding="utf-8")
    command = [sys.executable, "-m", "mypy", "--config-file", str(ROOT / "pyproject.toml")]
    command += ["--cache-dir", str(tmp_path / "cache"), "--no-error-summary", str(probe)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
    assert done.returncode == 1, done.stdout + done.stderr
    assert 'module named "tomllib"' in done.stdout
    assert 'Module "typing" has no attribute "Self"' in done.stdout
    assert 'Module has no attribute "timeout"' in done.stdout


def test_ruff_with_the_projects_settings_refuses_syntax_python_3_10_lacks() -> None:
    ruff = shutil.which("ruff", path=str(Path(sys.executable).parent)) or shutil.which("ruff")
    if ruff is None:
        pytest.skip("ruff is not installed (the dev extra)")
    source = "try:\n    pass\nexcept* ValueError:\n    pass\n"
    command = [ruff, "check", "--no-cache", "--stdin-filename", str(ROOT / "host_sdk" / "probe.py"), "-"]
    done = subprocess.run(command, input=source, capture_output=True, text=True, cwd=ROOT, timeout=120, check=False)
    assert done.returncode == 1 and "Cannot use `except*` on Python 3.10" in done.stdout + done.stderr


def test_venv_sh_refuses_the_opencv_wheel_in_a_venv_that_sees_the_systems_packages(tmp_path: Path) -> None:
    """SYSTEM_SITE_PACKAGES=1 keeps the system's numpy and OpenCV: the extras that bring PyPI's
    OpenCV (and its numpy 2) are refused before anything is made or installed."""
    env = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "SYSTEM_SITE_PACKAGES": "1"}
    for extras in ("vision", "tools,console", "dev"):
        done = subprocess.run(
            ["bash", str(ROOT / "scripts" / "venv.sh"), extras],
            env=env,
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
        )
        assert done.returncode == 1, done.stdout + done.stderr
        assert "brings PyPI's OpenCV, whose numpy 2 would replace the system's" in done.stderr
        assert "creating" not in done.stdout
    script = (ROOT / "scripts" / "venv.sh").read_text(encoding="utf-8")
    assert '--constraint "$VENV/constraints-system.txt"' in script and "--system-site-packages" in script
