"""`roverlink follow` end to end on the emulator (virtual clock, deterministic): the robot keeps the
target in view and touches nothing, including in the case the PiCar team could not handle; the
PiCar's published approach, on the same world, turns away from its own target."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from roverlink.cli import main

WORLDS = Path(__file__).resolve().parents[3] / "examples" / "worlds"


def follow(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, Any]:
    assert main(["follow", "--json", "--quiet", *args]) == 0
    out: dict[str, Any] = json.loads(capsys.readouterr().out)
    return out


def test_target_straight_ahead_inside_the_picar_threshold(capsys: pytest.CaptureFixture[str]) -> None:
    """The target starts 0.8 m ahead of the PiCar's lidar (its obstacle threshold was 1.3 m) and
    walks away down a hall: RoverLink follows it; the PiCar team's approach sees an obstacle and turns."""
    world = str(WORLDS / "follow_ahead.toml")
    ours = follow(capsys, "--world", world, "--profile", "picar", "--duration", "25")
    assert ours["collisions"] == 0
    assert ours["first_sight_s"] < 0.5
    assert ours["in_view_fraction"] > 0.95
    assert ours["follow_error_mean_m"] < 0.2
    assert ours["mode_s"].get("avoid", 0.0) < 1.0  # it never steered round its own target
    theirs = follow(capsys, "--world", world, "--profile", "picar", "--duration", "25", "--pilot", "picar-2018")
    assert theirs["in_view_fraction"] < 0.5
    # It turns away (2.5 s of turning here; how long it keeps turning after it has run into the
    # hall's wall depends on how it met the wall).
    assert theirs["mode_s"]["left"] + theirs["mode_s"]["right"] > 2.0


@pytest.mark.parametrize(("profile", "seed"), [("diffdrive-tb6612", 10), ("picar", 11)])
def test_follows_in_a_random_world(capsys: pytest.CaptureFixture[str], profile: str, seed: int) -> None:
    m = follow(capsys, "--world", f"random:{seed}", "--seed", str(seed), "--profile", profile, "--duration", "20")
    assert m["collisions"] == 0 and m["failsafes"] == 0
    assert m["first_sight_s"] is not None
    assert m["in_view_fraction"] >= 0.9
    assert m["distance_m"] > 0.5
    assert m["ground_truth"]


def test_bad_arguments(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["follow", "--duration", "-1"])
    assert exc.value.code == 2
    # A robot needs a target (its lidar and camera may come from the URL or the robot file:
    # tests/roverlink/cli/test_robot_sensors.py).
    assert main(["follow", "--url", "loop://", "--quiet"]) == 2
    assert "roverlink follow: on a robot give one of --template, --select, --target" in capsys.readouterr().err
    # An emu:// robot follows the target its world has; a person or a face it has not.
    emulated = "emu://picar?world=random:3&camera=320x240&lidar=ydlidar-f4"
    assert main(["follow", "--url", emulated, "--target", "person", "--quiet"]) == 2
    assert "--target needs a robot's camera: the emulated target is a rendered cylinder" in capsys.readouterr().err
    assert main(["follow", "--world", "random:x", "--quiet"]) == 1
    assert "random:SEED" in capsys.readouterr().err


def test_an_emu_url_robot_follows_its_worlds_target(capsys: pytest.CaptureFixture[str]) -> None:
    """`follow --url emu://...` with no target given: the photo of the target the emulated robot
    serves (`endpoints["target"]`), as examples/follow.py takes it."""
    url = "emu://picar?clock=virtual&world=random:3&camera=320x240&lidar=ydlidar-f4"
    assert main(["follow", "--url", url, "--duration", "12", "--json", "--quiet"]) == 0
    m = json.loads(capsys.readouterr().out)
    assert m["first_sight_s"] is not None and m["distance_m"] > 0.5
