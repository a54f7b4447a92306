"""Shared pytest configuration.

Hypothesis profiles, chosen with the HYPOTHESIS_PROFILE environment variable:

* ``ci`` (default): 100 examples per property, no deadline; quick enough for every push.
* ``thorough``: 2000 examples per property, for a nightly run or after touching the codec.

    HYPOTHESIS_PROFILE=thorough pytest -q tests/protocol/codec
"""

from __future__ import annotations

import os

try:
    from hypothesis import HealthCheck, settings
except ImportError:  # hypothesis is a dev extra: suites that do not use it still run without it
    settings = None  # type: ignore[assignment,misc]

PROFILE_ENV = "HYPOTHESIS_PROFILE"
PROFILE = os.environ.get(PROFILE_ENV, "ci")

if settings is not None:
    settings.register_profile(
        "ci",
        max_examples=100,
        deadline=None,
        derandomize=False,
        suppress_health_check=[HealthCheck.too_slow],
    )
    settings.register_profile(
        "thorough",
        max_examples=2000,
        deadline=None,
        derandomize=False,
        suppress_health_check=[HealthCheck.too_slow],
    )
    settings.load_profile(PROFILE)


def pytest_report_header() -> str:
    if settings is None:
        return "hypothesis: not installed"
    return f"hypothesis profile: {PROFILE} (set {PROFILE_ENV} to change)"
