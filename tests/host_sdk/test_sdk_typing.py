"""Typing for robot programs: after the README's install (scripts/venv.sh), `mypy --strict` on a
user's program finds host_sdk and checks what it uses: `transport.endpoints`, `robot.emulator`
(host_sdk.emulated), the pytest plugin's fixtures and the testing helpers."""

from __future__ import annotations

import importlib.metadata
import importlib.util
import json
import subprocess
import sys
import sysconfig
import textwrap
from pathlib import Path

import pytest

from host_sdk import Robot
from host_sdk.transport import Transport
from host_sdk.transport.plugins import PluginTransport

ROBOT_PROGRAM = """
    from collections.abc import Mapping
    from typing import assert_type

    from host_sdk import Robot
    from host_sdk.emulated import EmulatorHandle

    with Robot.connect("emu://picar?clock=virtual&imu=jy901") as robot:
        ports = robot.transport.endpoints
        assert_type(ports, Mapping[str, str])
        imu_url: str = ports["imu"]
        robot.arm()
        robot.drive(0.2, 0.0)
        emu = robot.emulator
        assert_type(emu, EmulatorHandle | None)
        if emu is not None:
            assert_type(emu.truth.plant.x_m, float)
            world = emu.truth.world
            collisions = world.collisions if world is not None else ()
            emu.set_stand(True)
            emu.cut_link()
"""

ROBOT_TEST = """
    from emulator import Emulator
    from hypothesis import given

    from host_sdk import Robot
    from host_sdk.emulated import EmulatorHandle
    from host_sdk.testing import Step, emulated_robot, run_steps
    from host_sdk.testing import strategies as rls


    def handle(emu: Emulator) -> EmulatorHandle:
        return emu  # the emulator has every member the Protocol declares


    def test_fixtures(roverlink_robot: Robot, roverlink_emulator: EmulatorHandle) -> None:
        roverlink_robot.arm()
        roverlink_emulator.reset_mcu()
        truth = roverlink_emulator.truth
        state = truth.firmware.state if truth.firmware is not None else None


    @given(rls.command_sequences("picar"))
    def test_property(steps: list[Step]) -> None:
        with emulated_robot(profile="picar", armed=True) as robot:
            run_steps(robot, steps)
"""


@pytest.fixture(scope="module")
def mypy_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    if importlib.util.find_spec("mypy") is None:
        pytest.skip("mypy is not installed (the dev extra)")
    return tmp_path_factory.mktemp("mypy_cache")


def _mypy_strict(tmp_path: Path, cache: Path, source: str) -> subprocess.CompletedProcess[str]:
    program = tmp_path / "program.py"
    program.write_text(textwrap.dedent(source), encoding="utf-8")
    # Run where a user would: outside the checkout, so host_sdk is found through the install
    # (and PYTHONPATH, as inherited) only.
    command = [sys.executable, "-m", "mypy", "--strict", "--cache-dir", str(cache), str(program)]
    return subprocess.run(command, cwd=tmp_path, capture_output=True, text=True, timeout=600, check=False)


def test_mypy_strict_passes_on_a_robot_program(tmp_path: Path, mypy_cache: Path) -> None:
    result = _mypy_strict(tmp_path, mypy_cache, ROBOT_PROGRAM)
    assert result.returncode == 0, result.stdout + result.stderr


def test_mypy_strict_passes_on_a_robot_test(tmp_path: Path, mypy_cache: Path) -> None:
    result = _mypy_strict(tmp_path, mypy_cache, ROBOT_TEST)
    assert result.returncode == 0, result.stdout + result.stderr


def test_the_editable_install_is_one_mypy_can_follow() -> None:
    """scripts/venv.sh installs with editable_mode=strict: a .pth naming a tree of links to the
    packages, not the default import hook (a `__editable___*_finder.py`), which mypy cannot see
    through, nor the whole checkout (its tests, tools and benchmarks importable)."""
    # The install in this interpreter's site-packages (not an egg-info a build left in the checkout).
    found = list(importlib.metadata.distributions(name="roverlink", path=[sysconfig.get_paths()["purelib"]]))
    if not found:
        pytest.skip("roverlink is not installed (tests run from the source tree)")
    dist = found[0]
    direct_url = json.loads(dist.read_text("direct_url.json") or "{}")
    if not direct_url.get("dir_info", {}).get("editable"):
        return  # a normal install: the packages are in site-packages, where mypy looks
    files = [Path(str(dist.locate_file(f))) for f in dist.files or []]
    finders = [f.name for f in files if f.name.startswith("__editable__") and f.name.endswith("_finder.py")]
    assert not finders, f"an import-hook editable install ({finders}): run scripts/venv.sh again"
    paths = [line for f in files if f.suffix == ".pth" for line in f.read_text().splitlines() if line.strip()]
    assert any((Path(p) / "host_sdk" / "__init__.py").is_file() for p in paths), paths
    assert not [p for p in paths if any((Path(p) / name).exists() for name in ("tests", "tools", "benchmarks"))], paths


def test_the_scripts_install_in_strict_mode() -> None:
    scripts = Path(__file__).resolve().parents[2] / "scripts"
    assert "EDITABLE_MODE=strict" in (scripts / "editable.sh").read_text(encoding="utf-8")
    for name in ("venv.sh", "test_pythons.sh", "test_system_opencv.sh"):
        script = (scripts / name).read_text(encoding="utf-8")
        assert "source" in script and "editable.sh" in script and 'editable_mode="$EDITABLE_MODE"' in script, name
        assert "editable_mode=compat" not in script, name


def test_every_editable_install_the_docs_show_is_one_mypy_can_follow() -> None:
    """A user who installs by hand, as the README or the docs show, gets the same strict install."""
    root = Path(__file__).resolve().parents[2]
    lines = [
        (doc.name, line)
        for doc in [root / "README.md", *sorted((root / "docs").glob("*.md"))]
        for line in doc.read_text(encoding="utf-8").splitlines()
        if "pip install" in line and " -e " in line
    ]
    assert any(name == "README.md" for name, _ in lines)
    assert [(n, line) for n, line in lines if "editable_mode=strict" not in line] == []


# == transport.endpoints ============================================================================
class _Cable(Transport):
    url = "/dev/ttyACM0"

    def read(self, timeout_s: float) -> bytes:
        return b""

    def write(self, data: bytes) -> None:
        return None

    def close(self) -> None:
        return None


def test_a_transport_without_sensors_has_no_endpoints() -> None:
    assert dict(_Cable().endpoints) == {}


def test_an_emulated_robot_lists_its_sensors_in_transport_endpoints() -> None:
    with Robot.connect("emu://picar?clock=virtual&imu=jy901&lidar=rplidar-a1") as robot:
        transport = robot.transport
        assert isinstance(transport, PluginTransport)
        assert set(transport.endpoints) == {"imu", "lidar"}
        assert transport.endpoints["imu"].startswith("emudev://")
