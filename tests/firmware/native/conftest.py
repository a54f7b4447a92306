"""The C++ codec driver, built once and run behind a pipe for the whole session."""

from __future__ import annotations

import tempfile
from collections.abc import Iterator

import pytest

from tests.support.rl_codec import RL_CODEC, RlCodec, require_make


@pytest.fixture(scope="session")
def tools_built() -> None:
    require_make("tools")


@pytest.fixture(scope="session")
def codec(tools_built: None) -> Iterator[RlCodec]:
    with tempfile.TemporaryFile() as stderr:
        tool = RlCodec(RL_CODEC, stderr)
        try:
            yield tool
        finally:
            code = tool.quit() if tool.proc.poll() is None else tool.proc.returncode
            errors = tool.stderr_text()
        assert code == 0, f"rl_codec exited with {code}:\n{errors}"
        assert errors == "", f"rl_codec wrote to stderr (sanitizer report?):\n{errors}"
