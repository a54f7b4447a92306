"""`roverlink follow --target person|face`: the pilot it makes, and the command line's checks."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from host_sdk import RobotDescription
from host_sdk.autonomy import FollowPilot
from host_sdk.geometry import RobotGeometry
from host_sdk.perception.class_tracker import ClassTracker
from roverlink.cli import main
from roverlink.follow.app import FollowSettings, RobotPorts, make_pilot, run_emulated, run_robot
from roverlink.follow.baseline import PiCarBaseline
from tests.host_sdk.autonomy.photos import needs_detectors

ROBOTS = Path(__file__).resolve().parents[3] / "protocol" / "robots"


def geometry() -> RobotGeometry:
    return RobotGeometry.from_description(RobotDescription.load(ROBOTS / "diffdrive-tb6612.toml"))


@needs_detectors
@pytest.mark.parametrize(("kind", "height_m"), [("person", 1.7), ("face", 0.16)])
def test_a_target_kind_makes_a_detecting_tracker_with_the_kinds_height(kind: str, height_m: float) -> None:
    pilot = make_pilot("roverlink", geometry(), None, FollowSettings(target=kind))
    assert isinstance(pilot, FollowPilot) and isinstance(pilot.tracker, ClassTracker)
    assert pilot.tracker.kind == kind and pilot.tracker.height_m == height_m
    given = make_pilot("roverlink", geometry(), None, FollowSettings(target=kind, target_height_m=1.5))
    assert isinstance(given, FollowPilot) and isinstance(given.tracker, ClassTracker)
    assert given.tracker.height_m == 1.5
    baseline = make_pilot("picar-2018", geometry(), None, FollowSettings(target=kind))
    assert isinstance(baseline, PiCarBaseline) and isinstance(baseline.tracker, ClassTracker)


@needs_detectors
def test_for_target_is_the_library_way() -> None:
    pilot = FollowPilot.for_target(geometry(), "face", follow_gap_m=0.8)
    assert isinstance(pilot.tracker, ClassTracker) and pilot.tracker.kind == "face"
    assert pilot.follower.params.follow_gap_m == 0.8


def test_one_target_only_and_none_on_the_emulator() -> None:
    ports = RobotPorts("/dev/null-board", "/dev/null-lidar", "/dev/null-camera")
    with pytest.raises(ValueError, match="one of them"):  # before anything is opened
        run_robot(ports, "picar", select=(1, 1, 10, 10), settings=FollowSettings(target="face"))
    with pytest.raises(ValueError, match="one of them"):
        run_robot(ports, "picar")
    with pytest.raises(ValueError, match="rendered shape"):
        run_emulated("picar", "random:3", settings=FollowSettings(target="person"))


def test_the_command_line_checks_the_target(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    assert main(["follow", "--target", "face", "--duration", "1", "--quiet"]) == 2
    assert "--target needs a robot's camera" in capsys.readouterr().err
    assert main(["follow", "--select", "140,90,40,60", "--duration", "1", "--quiet"]) == 2
    assert "--select is for a robot's camera" in capsys.readouterr().err
    robot = ["follow", "--url", "/dev/null", "--lidar", "/dev/null", "--camera", "0"]
    assert main([*robot, "--target", "face", "--select", "1,1,10,10"]) == 2
    assert "one of --template, --select, --target" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        main([*robot, "--target", "cat"])
    assert exc.value.code == 2
    assert "invalid choice: 'cat'" in capsys.readouterr().err
    (tmp_path / "target.png").write_text("not an image")
    assert main([*robot, "--template", str(tmp_path / "target.png")]) == 2
    assert f"cannot read the image {tmp_path / 'target.png'}" in capsys.readouterr().err


def test_a_selected_box_outside_the_cameras_frame_is_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    import cv2

    cv2.imwrite(str(tmp_path / "0001.jpg"), np.zeros((240, 320, 3), np.uint8))  # a replayed 320x240 camera
    robot = ["follow", "--url", "emu://picar?clock=virtual", "--lidar", "/dev/null", "--camera", str(tmp_path)]
    assert main([*robot, "--select", "300,200,50,60"]) == 1  # found once the camera gave its frame
    err = capsys.readouterr().err
    assert "--select" in err and "300,200,50,60" in err and "320x240" in err, err
