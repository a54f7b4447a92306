"""The examples built once per test session (the budgets and the simulated-MCU tests share them)."""

from __future__ import annotations

import pytest

from roverlink import firmware
from tests.support.avr_build import EXAMPLES, require_toolchain


@pytest.fixture(scope="session")
def example_builds(tmp_path_factory: pytest.TempPathFactory) -> dict[str, firmware.BuildResult]:
    """Every example for its own board, built once per session (objects come from the build cache)."""
    require_toolchain()
    out = tmp_path_factory.mktemp("firmware")
    results: dict[str, firmware.BuildResult] = {}
    failures: list[str] = []
    for name in EXAMPLES:
        try:
            results[name] = firmware.build_example(name, out_dir=out / name)
        except firmware.CompileError as exc:
            failures.append(f"{name}: {exc}")
    if failures:
        pytest.fail("examples that do not build:\n" + "\n\n".join(failures), pytrace=False)
    return results
