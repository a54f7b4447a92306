"""`roverlink follow` re-arms by itself only when asked (--rearm), and says so at the start."""

from __future__ import annotations

import pytest

from roverlink.cli import main


def test_rearm_is_an_opt_in_said_at_the_start(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["follow", "--world", "random:3", "--duration", "1", "--quiet", "--rearm"]) == 0
    assert "--rearm: the robot is armed again by itself" in capsys.readouterr().err
    assert main(["follow", "--world", "random:3", "--duration", "1", "--quiet"]) == 0
    assert "--rearm" not in capsys.readouterr().err
