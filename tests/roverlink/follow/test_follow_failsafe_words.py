"""A follow run that bumps into something says what happened: ControlLoop puts the failsafe in words
with what the lidar sees at the footprint, and `roverlink follow`'s progress lines print it."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest

from host_sdk import Robot
from host_sdk.autonomy import FollowPilot
from host_sdk.geometry import robot_geometry
from host_sdk.pose import Pose
from host_sdk.sensors import CameraSource, Lidar
from roverlink.commands.follow import _progress
from roverlink.follow.metrics import FollowMetrics
from roverlink.follow.run import run_follow
from tests.host_sdk.console.test_console_guard import CYLINDER, FORWARD_M_S, WORDS

pytest.importorskip("cv2")


class Straight(FollowPilot):
    """The follow pilot's scan handling, driving straight ahead whatever it sees."""

    def command(self, pose: Pose) -> tuple[float, float, str]:
        return FORWARD_M_S, 0.0, "straight"


def test_a_bump_in_a_follow_run_is_printed_with_what_the_lidar_saw(tmp_path: Path) -> None:
    world = CYLINDER.write(tmp_path)
    url = f"emu://diffdrive-tb6612?clock=virtual&seed=1&world={world}&lidar=rplidar-a1&camera=320x240"
    out = io.StringIO()
    with Robot.connect(url, clamp=True) as robot:
        follow = FollowPilot.for_robot(robot_geometry(robot), np.full((40, 30, 3), 128, dtype=np.uint8))
        pilot = Straight(follow.scan_filter, follow.tracker, follow.follower)
        lidar = Lidar.open(robot.transport.endpoints["lidar"], "rplidar-a1")
        camera = CameraSource(robot.transport.endpoints["camera"])
        metrics = run_follow(
            robot,
            lidar,
            camera,
            pilot,
            duration_s=8.0,
            metrics=FollowMetrics("straight", "diff"),
            progress=_progress(out, rearm=False),
        )
        lidar.close()
        camera.close()
    assert metrics.failsafes >= 1
    said = [line.strip() for line in out.getvalue().splitlines() if "failsafe" in line]
    assert said and said[0].startswith(f"failsafe ENCODER_FAULT: {WORDS}; the lidar sees an obstacle "), said
    assert "ahead of the body, inside the footprint's 0.08 m margin" in said[0], said
    # Said once in full, with what happens now; the lines after it say the robot is disarmed.
    assert said[0].endswith("; disarmed for the rest of the run: run it again, or with --rearm"), said
    later = out.getvalue().split(said[0], 1)[1]
    assert "failsafe ENCODER_FAULT" not in later and "(disarmed after the failsafe)" in later
