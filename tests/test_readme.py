"""The README's example runs and prints what its comments claim."""

from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

README = Path(__file__).resolve().parent.parent / "README.md"


def test_readme_example_runs_as_documented() -> None:
    text = README.read_text(encoding="utf-8")
    block = re.search(r"```python\n(.*?)```", text, re.S)
    assert block, "README has a python example"
    code = block.group(1)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, str(README), "exec"), {})
    printed = out.getvalue()
    assert "1 SetWheelSpeeds(left_mm_s=300, right_mm_s=280)" in printed
    assert "2 Log(level=<LogLevel.INFO: 1>, text='hello')" in printed
    assert "frames_ok=2" in printed
    claimed = re.search(r"print\(err\)\s+# (.*)", code)
    assert claimed and claimed.group(1).strip() in printed


def test_readme_commands_exist() -> None:
    text = README.read_text(encoding="utf-8")
    assert "roverlink roundtrip" in text
    assert "bash scripts/test.sh" in text
    ci = (README.parent / ".ci" / "run").read_text(encoding="utf-8")
    assert "bash scripts/test.sh" in ci
