"""Drive a 1 m square on odometry (counter-clockwise).

.venv/bin/python examples/drive_square.py                                          # the emulated diff-drive car
.venv/bin/python examples/drive_square.py "emu://diffdrive-tb6612?clock=virtual"   # the same, as fast as the CPU allows
.venv/bin/python examples/drive_square.py "emu://diffdrive-bts7960?clock=virtual"  # the SLAM robot (lockstep)
.venv/bin/python examples/drive_square.py "emu://picar?clock=virtual"              # the Ackermann PiCar
.venv/bin/python examples/drive_square.py /dev/ttyACM0                             # a real board

A differential drive turns in place at the corners; an Ackermann robot cannot, so it takes each
corner as an arc at its tightest steering (drive() with clamp=True holds the steering at its stop).
"""

from __future__ import annotations

import math
import sys

from host_sdk import Ackermann, Robot


def wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def main(url: str = "emu://") -> None:
    with Robot.connect(url) as robot:
        print(f"connected to {robot.identity.robot_name}, boot_id 0x{robot.identity.boot_id:08X}")
        steered = isinstance(robot.kinematics, Ackermann)
        robot.arm()
        robot.odometry.reset()
        heading = 0.0
        for side in range(4):
            start = robot.odometry.pose
            while math.hypot(robot.odometry.pose.x_m - start.x_m, robot.odometry.pose.y_m - start.y_m) < 1.0:
                # hold the heading while driving straight; commands must be renewed in a loop
                robot.drive(0.3, 2.0 * wrap(heading - robot.odometry.pose.theta_rad), clamp=True)
                robot.wait_feedback()
            heading += math.pi / 2
            if steered:  # forward along the tightest arc until the heading is reached
                while wrap(heading - robot.odometry.pose.theta_rad) > math.radians(1):
                    robot.drive(0.25, 10.0, clamp=True)
                    robot.wait_feedback()
            else:  # turn in place, slowing down near the heading
                while abs(error := wrap(heading - robot.odometry.pose.theta_rad)) > math.radians(1):
                    robot.drive(0.0, math.copysign(min(1.2, 3 * abs(error) + 0.1), error), clamp=True)
                    robot.wait_feedback()
            pose = robot.odometry.pose
            print(
                f"side {side + 1}: x={pose.x_m:+.3f} m y={pose.y_m:+.3f} m "
                f"heading={math.degrees(pose.theta_rad):.1f} deg"
            )
        robot.stop()


if __name__ == "__main__":
    main(*sys.argv[1:2])
