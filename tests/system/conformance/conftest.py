"""The conformance suite: one scenario suite, three backends (conformance_backends.py; the scenarios
in conformance_scenarios.py and conformance_board_scenarios.py, run by conformance_runner.py).

Each backend is a fresh robot per test; the Python emulator's result of each scenario is the
reference, computed once per session (conformance_runner.reference).
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest
from conformance_backends import BACKENDS, Backend, make_backend
from conformance_runner import PROFILE


@pytest.fixture(params=BACKENDS)
def tb6612(request: pytest.FixtureRequest) -> Iterator[Backend]:
    """A fresh TB6612 robot on each backend."""
    b = make_backend(request.param, PROFILE)
    yield b
    b.close()
