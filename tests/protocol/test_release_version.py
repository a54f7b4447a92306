"""The release's version is written once, in the spec's [release], and generated everywhere else."""

from __future__ import annotations

import ast
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from protocol.__main__ import main
from protocol.generated.version import LICENSE, VERSION, __version__
from protocol.generator import generate, loader
from protocol.generator.emit import release

ROOT = generate.ROOT
SPEC_DIR = Path("protocol/spec")
PLACES = (
    release.VERSION_PY,
    release.VERSION_H,
    release.LIBRARY_PROPERTIES,
    release.LIBRARY_JSON,
    release.ROS_PACKAGE_XML,
)


def checkout(tmp: Path) -> Path:
    """The spec, the reference robots' files, the ROS package's hand-written package.xml, and
    everything generated from them."""
    for name in ("roverlink.toml", "hardware.toml"):
        (tmp / SPEC_DIR).mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / SPEC_DIR / name, tmp / SPEC_DIR / name)
    shutil.copytree(ROOT / "protocol" / "robots", tmp / "protocol" / "robots")
    (tmp / release.ROS_PACKAGE_XML).parent.mkdir(parents=True)
    shutil.copy(ROOT / release.ROS_PACKAGE_XML, tmp / release.ROS_PACKAGE_XML)
    assert run("generate", tmp) == 0
    assert run("check", tmp) == 0
    return tmp


def run(command: str, root: Path) -> int:
    return main([command, "--spec", str(root / SPEC_DIR / "roverlink.toml"), "--root", str(root)])


@pytest.mark.parametrize("place", PLACES)
def test_a_version_edited_in_one_place_only_fails_the_check(
    place: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    root = checkout(tmp_path)
    path = root / place
    text = path.read_text(encoding="utf-8")
    edited = text.replace(__version__, "9.9.9", 1)
    if place == release.VERSION_H:  # the numbers the firmware reports, beside the string
        edited = edited.replace(f"MAJOR {VERSION[0]}", "MAJOR 9")
    assert edited != text
    path.write_text(edited, encoding="utf-8")
    capsys.readouterr()
    assert run("check", root) == 1
    assert f"stale: {place}" in capsys.readouterr().err


def test_the_spec_alone_moves_every_place(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    root = checkout(tmp_path)
    spec_file = root / SPEC_DIR / "roverlink.toml"
    spec_file.write_text(spec_file.read_text().replace(f'version = "{__version__}"', 'version = "1.2.3"'))
    capsys.readouterr()
    assert run("check", root) == 1
    err = capsys.readouterr().err
    for place in PLACES:
        assert f"stale: {place}" in err
    assert run("generate", root) == 0
    assert '__version__: Final = "1.2.3"' in (root / release.VERSION_PY).read_text()
    assert "#define ROVERLINK_FIRMWARE_VERSION_MINOR 2" in (root / release.VERSION_H).read_text()
    assert "\nversion=1.2.3\n" in (root / release.LIBRARY_PROPERTIES).read_text()
    assert '"version": "1.2.3"' in (root / release.LIBRARY_JSON).read_text()
    assert "<version>1.2.3</version>" in (root / release.ROS_PACKAGE_XML).read_text()


@pytest.mark.parametrize("bad", ["1.2", "1.2.3.4", "1.256.0", "01.2.3", "1.2.x", ""])
def test_a_bad_release_version_is_refused_naming_it(bad: str) -> None:
    text = generate.SPEC.read_text(encoding="utf-8").replace(f'version = "{__version__}"', f'version = "{bad}"')
    with pytest.raises(loader.SpecError, match=r"release.*MAJOR\.MINOR\.PATCH"):
        loader.parse(text, "protocol/spec/roverlink.toml")


def test_the_release_version_is_not_part_of_the_spec_hash() -> None:
    text = generate.SPEC.read_text(encoding="utf-8")
    bumped = text.replace(f'version = "{__version__}"', 'version = "7.8.9"')
    assert loader.parse(bumped, "x").spec_hash == loader.parse(text, "x").spec_hash


def test_every_package_reports_the_generated_version() -> None:
    import emulator.firmware.core
    import host_sdk
    import roverlink

    assert host_sdk.__version__ == roverlink.__version__ == __version__
    assert emulator.firmware.core.FIRMWARE_VERSION == VERSION
    pyproject = (ROOT / "pyproject.toml").read_text()
    assert 'dynamic = ["version"]' in pyproject
    assert 'version = { attr = "protocol.generated.version.__version__" }' in pyproject
    assert f'license = "{LICENSE}"' in pyproject and (ROOT / "LICENSE").read_text().startswith(f"{LICENSE} License")
    # The ROS package's setup.py takes version and licence from its package.xml.
    setup_py = ast.parse((ROOT / "ros2/roverlink_ros/setup.py").read_text())
    keywords = {k.arg: k.value for n in ast.walk(setup_py) if isinstance(n, ast.Call) for k in n.keywords}
    for key in ("version", "license"):
        assert isinstance(keywords[key], ast.Call) and "findtext" in ast.unparse(keywords[key]), key


def test_the_installed_distribution_has_the_spec_version() -> None:
    from importlib.metadata import version

    assert version("roverlink") == __version__


def test_no_other_tracked_file_writes_the_version_down() -> None:
    """A literal release version anywhere else in code or metadata would drift from the spec."""
    files = subprocess.run(
        ["git", "ls-files", "*.py", "*.toml", "*.xml", "*.h", "*.cpp", "*.ino", "*.properties", "*.json", "*.cfg"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    literal = re.compile(rf"(?<![\d.]){re.escape(__version__)}(?![\d.])")
    allowed = {*PLACES, str(SPEC_DIR / "roverlink.toml")}
    found = [f for f in files if f not in allowed and literal.search((ROOT / f).read_text(errors="replace"))]
    assert not found, f"the release version {__version__} is written down in {found}: import it or generate it"


def test_setup_py_of_the_ros_package_reads_its_manifest(tmp_path: Path) -> None:
    """The ROS package's metadata as setuptools sees it (no colcon here): version and licence."""
    # colcon builds the package with the ROS Python's setuptools; venvs from 3.12 on have none
    pytest.importorskip("setuptools", reason="the ROS package's setup.py needs setuptools")
    out = subprocess.run(
        [sys.executable, "setup.py", "--version", "--license"],
        cwd=ROOT / "ros2/roverlink_ros",
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    assert out == [__version__, LICENSE]
