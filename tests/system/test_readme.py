"""The README's examples run and print what their comments claim."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

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
    assert "DiffDriveTB6612 0.1.0" in printed
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
    assert [ln for ln in ci.splitlines() if ln and not ln.startswith(("#", "set ", "cd "))] == ["bash scripts/test.sh"]
