"""Tests wait one way: tests/support/wait.py (a condition with a deadline), never their own loop."""

from __future__ import annotations

import re
from pathlib import Path

TESTS = Path(__file__).resolve().parents[2]
WAIT = TESTS / "support" / "wait.py"
# A deadline built by hand: `x = time.monotonic() + ...` (a loop that runs out the clock is next).
OWN_DEADLINE = re.compile(r"^\s*\w*deadline\w*\s*=\s*time\.monotonic\(\)\s*\+", re.MULTILINE | re.IGNORECASE)


def test_no_test_builds_its_own_deadline() -> None:
    found = [
        f"{path.relative_to(TESTS)}:{text.count(chr(10), 0, m.start()) + 1}"
        for path in sorted(TESTS.rglob("*.py"))
        if path != WAIT
        for text in [path.read_text(encoding="utf-8")]
        for m in OWN_DEADLINE.finditer(text)
    ]
    assert not found, f"use tests.support.wait (wait_until or Deadline) instead of a hand-made deadline: {found}"
