"""The world: scenario files, random worlds, the moving target, collisions and the bumper."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from emulator.world import ScenarioError, load_world, parse_scenario
from emulator.world.generate import ROBOT_CLEARANCE_M, solvable
from emulator.world.raycast import nearest
from host_sdk.robot import Robot

ROOM = Path(__file__).resolve().parents[3] / "examples" / "worlds" / "room.toml"


def test_the_example_scenario_loads() -> None:
    scene = load_world(ROOM)
    assert scene.name == "room"
    assert [s.kind for s in scene.shapes] == ["wall", "wall", "box", "cylinder", "target"]
    assert scene.start == (1.0, 2.0, 0.0)
    # Straight ahead of the start: the target (r 0.12 m at x = 3.8) at t = 0, the far wall once it left.
    ahead = (np.array([[1.0, 2.0]]), np.array([[1.0, 0.0]]))
    t, shape, cos = nearest(scene, *ahead)
    assert scene.shapes[shape[0]].kind == "target" and t[0] == pytest.approx(2.68) and cos[0] == pytest.approx(1.0)
    scene.set_time(3.0)
    t, shape, _ = nearest(scene, *ahead)
    assert scene.shapes[shape[0]].name == "outer walls" and t[0] == pytest.approx(4.0)


@pytest.mark.parametrize(
    ("data", "field", "allowed"),
    [
        ({"boxes": [{"center": [1, 1], "size": [0.4]}]}, "boxes[0].size", "two numbers > 0"),
        ({"target": {"path": [[0, 0]], "mode": "zigzag"}}, "target.mode", "loop or bounce"),
        ({"cylinders": [{"center": [1, 1], "radius_m": -1}]}, "cylinders[0].radius_m", "a radius > 0"),
        ({"walls": [{"from": [0, 0], "to": [1, 1], "colour": "red"}]}, "walls[0].colour", '"#rrggbb"'),
        ({"rooms": []}, "rooms", "a top-level table"),
    ],
)
def test_scenario_errors_name_the_field(data: dict[str, object], field: str, allowed: str) -> None:
    with pytest.raises(ScenarioError, match=allowed) as info:
        parse_scenario(data)
    assert info.value.name == field
    assert isinstance(info.value, ValueError)


def test_random_worlds_are_solvable_and_reproducible() -> None:
    for seed in range(8):
        scene = load_world(f"random:{seed}")
        assert solvable(scene), seed
        assert scene.target is not None and scene.target.path.speed_m_s > 0
    a, b = load_world("random:11"), load_world("random:11")
    assert np.array_equal(a.segments, b.segments) and a.start == b.start
    assert not np.array_equal(a.segments, load_world("random:12").segments)


def test_no_random_world_walks_its_target_over_the_robots_start() -> None:
    # The target walks while the robot is being connected: a route across the start pose would
    # run into a robot that has not begun to move.
    for seed in range(50):
        scene = load_world(f"random:{seed}")
        assert scene.target is not None
        path, (sx, sy, _) = scene.target.path, scene.start
        walk = [path.pose_at(t)[:2] for t in np.arange(0.0, path.length_m / path.speed_m_s, 0.05)]
        closest = min(math.hypot(x - sx, y - sy) for x, y in walk)
        assert closest >= ROBOT_CLEARANCE_M + scene.target.radius_m - 0.01, (seed, closest)


def test_the_target_moves_along_its_path_at_its_speed() -> None:
    scene = load_world(ROOM)
    assert scene.target is not None
    path = scene.target.path
    x0, y0, _, _ = path.pose_at(0.0)
    x1, y1, _, speed = path.pose_at(1.0)
    assert (x0, y0) == (3.8, 2.0)
    assert math.hypot(x1 - x0, y1 - y0) == pytest.approx(0.2, abs=1e-9) and speed == 0.2
    assert path.pose_at(path.length_m / 0.2)[:2] == pytest.approx((3.8, 2.0))  # round the loop


def test_driving_into_a_wall_is_a_collision_and_the_bumper_stops_the_robot(tmp_path: Path) -> None:
    world = tmp_path / "corridor.toml"
    world.write_text("[world]\nsize_m = [3.0, 1.0]\n[start]\nx_m = 0.5\ny_m = 0.5\n", encoding="utf-8")
    with Robot.connect(f"emu://diffdrive-tb6612?clock=virtual&world={world}") as robot:
        emu = robot.emulator
        _drive_until_contact(robot, 0.4, 12.0)
        truth = emu.truth.world
        (hit,) = truth.collisions
        # The footprint (r 0.12 m, 0.03 m ahead of the pose point) meets the wall at x = 3.
        assert hit.x_m == pytest.approx(3.0, abs=0.01) and hit.y_m == pytest.approx(0.5, abs=0.05)
        assert hit.kind == "wall" and 0.2 < hit.speed_m_s < 0.6
        assert hit.closing_m_s == pytest.approx(hit.speed_m_s, rel=0.2)  # straight at it: driven into
        stopped_at = truth.x_m
        assert stopped_at == pytest.approx(3.0 - 0.12 - 0.03, abs=0.01)
        for _ in range(15):  # pushing on: the robot stays where the bumper stopped it
            robot.drive(0.4, 0.0)
            robot.wait_feedback()
        # (Pushing for half a second more would stall the wheels into ENCODER_FAULT, as on a robot.)
        assert emu.truth.world.x_m == pytest.approx(stopped_at, abs=0.002)
        assert len(emu.truth.world.collisions) == 1
        for _ in range(100):  # backing away is allowed
            robot.drive(-0.3, 0.0)
            robot.wait_feedback()
        assert emu.truth.world.x_m < stopped_at - 0.1
        assert not emu.truth.world.in_contact


def test_a_target_walking_into_a_standing_robot_is_a_contact_the_robot_was_run_into(tmp_path: Path) -> None:
    world = tmp_path / "crossing.toml"
    world.write_text(
        "[world]\nsize_m = [4.0, 2.0]\n[start]\nx_m = 2.0\ny_m = 1.0\n"
        '[target]\npath = [[3.5, 1.0], [0.5, 1.0]]\nspeed_m_s = 0.3\nmode = "bounce"\n',
        encoding="utf-8",
    )
    with Robot.connect(f"emu://diffdrive-tb6612?clock=virtual&world={world}") as robot:
        _drive_until_contact(robot, 0.0, 8.0)
        (hit,) = robot.emulator.truth.world.collisions
        assert hit.kind == "target" and hit.closing_m_s == pytest.approx(0.0, abs=0.01)


def _drive_until_contact(robot: Robot, linear_m_s: float, until_s: float) -> None:
    robot.arm()
    while not robot.emulator.truth.world.collisions and robot.now() < until_s:
        robot.drive(linear_m_s, 0.0)
        robot.wait_feedback()
