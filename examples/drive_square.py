"""Drive a 1 m square on odometry.

python examples/drive_square.py                       # the emulated diff-drive car
python examples/drive_square.py /dev/ttyACM0          # a real board
python examples/drive_square.py "emu://picar?clock=virtual"
"""

from __future__ import annotations

import math
import sys

from host_sdk import Robot


def wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def main(url: str = "emu://") -> None:
    with Robot.connect(url) as robot:
        print(f"connected to {robot.identity.robot_name}, boot_id 0x{robot.identity.boot_id:08X}")
        robot.arm()
        robot.odometry.reset()
        heading = 0.0
        for side in range(4):
            start = robot.odometry.pose
            while math.hypot(robot.odometry.pose.x_m - start.x_m, robot.odometry.pose.y_m - start.y_m) < 1.0:
                # hold the heading while driving straight; commands must be renewed in a loop
                robot.drive(0.3, 2.0 * wrap(heading - robot.odometry.pose.theta_rad))
                robot.wait_feedback()
            heading += math.pi / 2
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
