"""`roverlink emulate` says on stderr what happened to the robot, as it happens: a collision in its
world (which the board sees only as wheels that stopped: a failsafe) and the faults it injects,
those standing from the start too. The real command on a pty, driven through the SDK."""

from __future__ import annotations

import re
from pathlib import Path

from host_sdk import Robot, RoverLinkError
from tests.support.emulate import emulate
from tests.support.wait import Deadline

# The robot starts at (1.0, 1.5) facing +x; a post stands 0.7 m ahead of it.
WORLD = """
world = { size_m = [4.0, 3.0] }
start = { x_m = 1.0, y_m = 1.5, theta_deg = 0.0 }
cylinders = [{ name = "post", center = [1.7, 1.5], radius_m = 0.15 }]
"""
COLLISION = re.compile(r"t=(\d+\.\d+)s collision with post \(cylinder\) at \((\S+), (\S+)\) m, (\S+) m/s")
DEADLINE_S = 30.0


def test_emulate_prints_a_collision_and_the_standing_fault(tmp_path: Path) -> None:
    world = tmp_path / "post.toml"
    world.write_text(WORLD, encoding="utf-8")
    log = tmp_path / "stderr.txt"
    with (
        log.open("w") as err,
        emulate("--world", str(world), "--faults", "bitflip.m2h=1e-7", stderr=err) as board,
        Robot.connect(board.url, timeout_s=10.0) as robot,
    ):
        robot.arm()
        deadline = Deadline(DEADLINE_S)
        try:
            # The emulator writes the line in the pass that stops the robot, before the board's
            # next feedback can reach the host.
            while not COLLISION.search(log.read_text()) and not deadline.expired():
                robot.drive(0.3, 0.0)
                robot.wait_feedback()
        except RoverLinkError:
            pass  # the failsafe the stopped wheels cause
    text = log.read_text()
    hit = COLLISION.search(text)
    assert hit, text
    t_s, x_m, y_m, speed = (float(v) for v in hit.groups())
    assert 1.5 < x_m < 1.56 and abs(y_m - 1.5) < 0.05 and 0.1 < speed < 0.5, hit.group(0)
    assert 0.5 < t_s < DEADLINE_S
    assert "ENCODER_FAULT" in text  # says what the board will make of it
    assert "t=0.000s fault: flip 1e-05 % of the bits (MCU to host)" in text, text
