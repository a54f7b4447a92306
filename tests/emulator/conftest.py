"""Fixtures for the emulator suite. Everything runs on the virtual clock except the pty/socket tests."""

from __future__ import annotations

import pytest

from emulator import Emulator
from tests.support.hostlink import Host


@pytest.fixture
def emu() -> Emulator:
    return Emulator("diffdrive-tb6612", seed=1)


@pytest.fixture
def host(emu: Emulator) -> Host:
    return Host(emu)
