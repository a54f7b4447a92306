"""examples/console.py, a robot program serving the console, runs as its docstring says (on the
emulator) and is built from host_sdk alone."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
import urllib.error
import urllib.request
from pathlib import Path

import pytest

from tests.support.wait import wait_until

pytest.importorskip("aiohttp")
EXAMPLE = Path(__file__).resolve().parents[3] / "examples" / "console.py"


def test_the_example_imports_only_the_sdk() -> None:
    tops = set()
    for node in ast.walk(ast.parse(EXAMPLE.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module:
            tops.add(node.module.split(".")[0])
    assert "host_sdk" in tops and not tops & {"roverlink", "emulator"}


def test_the_example_serves_the_page_and_the_camera() -> None:
    url = re.search(r"--url '(emu://[^']+)'", EXAMPLE.read_text(encoding="utf-8"))
    assert url is not None
    proc = subprocess.Popen(
        [sys.executable, str(EXAMPLE), "--url", url.group(1), "--port", "0", "--duration", "30"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        found = re.match(r"open (http://127\.0\.0\.1:\d+/)", line)
        assert found, (line, proc.stderr.read() if proc.poll() is not None and proc.stderr else "")
        with urllib.request.urlopen(found.group(1), timeout=5) as page:
            assert b"RoverLink console" in page.read()

        def first_frame() -> bytes | None:  # the camera's first frame reaches the server through the loop
            try:
                with urllib.request.urlopen(found.group(1) + "api/frame.jpg", timeout=5) as shot:
                    return bytes(shot.read(3))
            except urllib.error.HTTPError as e:
                assert e.code == 503, e
                return None

        assert wait_until(first_frame, 20, "the camera's first frame", poll_s=0.1) == b"\xff\xd8\xff"
    finally:
        proc.terminate()
        proc.wait(timeout=20)
