"""`roverlink follow --robot FILE`: the emulated robot, the pilot's geometry and the lidar are the file's."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from host_sdk import RobotDescription
from roverlink.cli import main
from roverlink.follow import emulated
from roverlink.follow.app import geometry_for


def _new_picar(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> Path:
    path = tmp_path / "mine.toml"
    assert main(["robot", "new", str(path), "--from", "picar"]) == 0
    path.write_text(path.read_text().replace("radius_m = 0.19 ", "radius_m = 0.22 ", 1))
    capsys.readouterr()
    return path


def test_follow_runs_the_files_robot_on_the_emulator(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _new_picar(tmp_path, capsys)
    assert main(["follow", "--robot", str(path), "--duration", "5", "--json", "--quiet"]) == 0
    metrics = json.loads(capsys.readouterr().out)
    assert metrics["robot_file"] == str(path)
    assert metrics["profile"] == RobotDescription.load(path).name
    assert metrics["duration_s"] >= 5.0 and metrics["ground_truth"]


def test_the_emulated_robot_and_the_pilots_geometry_are_the_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    desc = RobotDescription.load(_new_picar(tmp_path, capsys))
    em = emulated.start(desc, "random:1", seed=1)
    try:
        assert em.emulator.profile.robot_file == desc.path
        assert em.robot.description == desc  # connected with the file: compared and applied
        assert em.truth.body.footprint_radius_m == pytest.approx(0.22)
        assert em.lidar_model == "ydlidar-f4"
        geo = geometry_for(em.robot, desc)
        assert geo.footprint.radius_m == pytest.approx(0.22)
        assert geo.camera == desc.camera_model()
        assert geo.curvatures  # the car's steering arcs, from the board's config
    finally:
        em.robot.close()


def test_a_bad_robot_file_exits_2_naming_its_problems(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _new_picar(tmp_path, capsys)
    path.write_text(path.read_text().replace("radius_m = 0.22 ", "radius_m = -1.0 ", 1))
    with pytest.raises(SystemExit) as exit_:
        main(["follow", "--robot", str(path), "--duration", "5", "--quiet"])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert str(path) in err and "radius_m" in err
    with pytest.raises(SystemExit) as exit_:
        main(["follow", "--robot", str(path), "--profile", "picar", "--quiet"])
    assert exit_.value.code == 2
