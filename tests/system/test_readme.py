"""The README's examples run and print what their comments claim."""

from __future__ import annotations

import contextlib
import io
import re
import subprocess
from pathlib import Path

import pytest

from protocol.errors import TOOLS_EXTRAS, MissingDependencyError
from protocol.generated.version import __version__
from protocol.toml import tomllib

README = Path(__file__).resolve().parents[2] / "README.md"


def _blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)


def _run(code: str) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, str(README), "exec"), {})
    return out.getvalue()


def test_readme_robot_example_runs_as_documented() -> None:
    code = next(b for b in _blocks() if "Robot.connect" in b)
    printed = _run(code)
    assert f"DiffDriveTB6612 {__version__}" in printed
    assert "odometry x = 0.5 m" in printed
    claimed = re.search(r"print\(err\)\s+# (.*)", code)
    assert claimed and claimed.group(1).strip() in printed


def test_readme_codec_example_runs_as_documented() -> None:
    code = next(b for b in _blocks() if "FrameDecoder" in b)
    printed = _run(code)
    assert "1 SetWheelSpeeds(left_mm_s=300, right_mm_s=280)" in printed
    assert "2 Log(level=<LogLevel.INFO: 1>, text='hello')" in printed
    assert "frames_ok=2" in printed
    claimed = re.search(r"print\(err\)\s+# (.*)", code)
    assert claimed and claimed.group(1).strip() in printed


def test_readme_commands_exist() -> None:
    text = README.read_text(encoding="utf-8")
    commands = re.search(r"## Two commands\n\n```sh\n(.*?)```", text, re.S)
    assert commands
    lines = [line.split("#")[0].strip() for line in commands.group(1).splitlines()]
    assert lines == ["bash scripts/demo.sh", "bash scripts/test.sh"]
    for script in ("demo.sh", "test.sh", "venv.sh"):
        assert (README.parent / "scripts" / script).is_file()
    assert "roverlink roundtrip" in text
    ci = (README.parent / ".ci" / "run").read_text(encoding="utf-8")
    # CI may only make missing parts failures (ROVERLINK_REQUIRE_*), not run anything else
    strict = re.compile(r"export ROVERLINK_REQUIRE_[A-Z0-9_]+=1")
    run = [ln for ln in ci.splitlines() if ln and not ln.startswith(("#", "set ", "cd ")) and not strict.fullmatch(ln)]
    assert run == ["bash scripts/test.sh"]


def _pyproject_extras() -> dict[str, list[str]]:
    with (README.parent / "pyproject.toml").open("rb") as f:
        extras: dict[str, list[str]] = tomllib.load(f)["project"]["optional-dependencies"]
    return extras


def test_readme_install_names_every_extra_and_no_other() -> None:
    text = README.read_text(encoding="utf-8")
    install = re.search(r"## Install\n(.*?)\n## ", text, re.S)
    assert install, "README has no Install section"
    table = set(re.findall(r"^\| `([a-z0-9-]+)` \|", install.group(1), re.M))
    named = {e for group in re.findall(r"roverlink\[([a-z0-9,-]+)\]", text) for e in group.split(",")}
    named |= {e for group in re.findall(r"-e '\.\[([a-z0-9,-]+)\]'", text) for e in group.split(",")}
    extras = set(_pyproject_extras())
    assert table == extras, f"README's extras table {sorted(table)} != pyproject.toml's {sorted(extras)}"
    assert named <= extras, f"README installs extras pyproject.toml does not have: {sorted(named - extras)}"
    assert 'PYTHON="${PYTHON:-python3}"' in (README.parent / "scripts" / "venv.sh").read_text(encoding="utf-8")


def test_the_tools_extra_is_the_extras_its_messages_name() -> None:
    """MissingDependencyError offers 'roverlink[tools]' for exactly the extras `tools` gathers."""
    extras = _pyproject_extras()
    assert sorted(extras["tools"]) == sorted(req for name in TOOLS_EXTRAS for req in extras[name])
    assert "'roverlink[tools]'" in str(MissingDependencyError("textual", "tui", "x"))
    assert "'roverlink[tools]'" not in str(MissingDependencyError("cv2", "vision", "the camera"))


def _section(title: str) -> str:
    text = README.read_text(encoding="utf-8")
    found = re.search(rf"^## {re.escape(title)}\n(.*?)(?=^## )", text, re.S | re.M)
    assert found, title
    return found.group(1)


def test_the_debian_python_hint_sits_under_the_two_commands() -> None:
    assert "PYTHON=/usr/bin/python3 bash scripts/demo.sh" in _section("Two commands")


def test_the_account_of_test_sh_names_what_it_installs_and_runs_and_how_long_it_takes() -> None:
    words = " ".join(_section("Two commands").split())
    for what in ("Chromium", "clang 14 with libFuzzer", "fuzzing", "console benchmarks", "25 minutes"):
        assert what in words, what
    testing = (README.parent / "docs" / "testing.md").read_text(encoding="utf-8")
    total = re.search(r"\*\*the full run, total\*\* \| \*\*([\d,]+)\*\*", testing)
    assert total, "docs/testing.md#time has the full run's total"
    seconds = int(total.group(1).replace(",", ""))
    assert f"about {round(seconds / 60)} minutes on a 2-core machine ({total.group(1)} s measured)" in words


def test_demo_sh_plot_installs_nothing_after_the_tests_dev_extra() -> None:
    """`dev` has matplotlib: a venv with it serves `--plot`'s `plot` extra without installing it again."""
    venv = README.parent / ".venv"
    stamps = list(venv.glob(".installed-strict-*dev*"))
    if not stamps:
        pytest.skip(".venv has no `dev` install (scripts/test.sh makes one)")
    result = subprocess.run(
        ["bash", "-c", 'source scripts/venv.sh plot,tui && echo "venv ok"'],  # a pair no install is stamped with
        cwd=README.parent,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.stdout.strip().splitlines() == ["venv ok"], result.stdout + result.stderr
