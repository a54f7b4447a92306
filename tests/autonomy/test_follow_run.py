"""The follow loop's pose history: a revolution or a frame is registered at the pose of its own time."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import cast

import pytest

from host_sdk import Robot
from roverlink.follow.run import PoseSource


def test_poses_between_control_steps_are_interpolated_not_rounded() -> None:
    odometry = SimpleNamespace(pose=SimpleNamespace(x_m=0.0, y_m=0.0, theta_rad=0.0))
    poses = PoseSource(cast(Robot, SimpleNamespace(odometry=odometry)), None)
    for i in range(5):  # turning at 1 rad/s and driving at 0.2 m/s, one pose per 50 ms control step
        t = 0.05 * i
        odometry.pose = SimpleNamespace(x_m=0.2 * t, y_m=0.0, theta_rad=math.pi - 0.1 + t)  # crosses pi
        poses.update(t)
    x, y, th = poses.at(0.12)
    assert x == pytest.approx(0.024) and y == 0.0
    assert th == pytest.approx(math.pi - 0.1 + 0.12)  # not the nearest step's, 0.1 or 0.15
    assert poses.at(-1.0)[0] == 0.0 and poses.at(9.0)[0] == pytest.approx(0.04)  # held beyond the history
