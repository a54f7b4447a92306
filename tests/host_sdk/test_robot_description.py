"""host_sdk.RobotDescription: a robot file with the SDK's kinematics, footprint and mounts."""

from __future__ import annotations

from pathlib import Path

import pytest

from host_sdk import RobotDescription, RobotFileError
from host_sdk.geometry import geometry
from host_sdk.profiles import kinematics_for
from protocol.robotfile import REFERENCES, reference_path


@pytest.mark.parametrize("name", REFERENCES)
def test_reference_files_give_the_reference_kinematics_and_geometry(name: str) -> None:
    robot = RobotDescription.load(reference_path(name))
    assert robot.kinematics() == kinematics_for(name)
    reference = geometry(name, kinematics_for(name))
    assert robot.body() == reference.footprint
    assert robot.lidar_mount() == reference.lidar_mount
    assert robot.camera_model() == reference.camera


def test_load_raises_the_robot_file_error(tmp_path: Path) -> None:
    with pytest.raises(RobotFileError, match="no such file"):
        RobotDescription.load(tmp_path / "missing.toml")
