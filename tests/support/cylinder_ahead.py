"""A room with one cylinder straight ahead of the robot's start: what a person drives into (the
teleop guard's closed-loop tests), and the robot's gap to it from the emulator's ground truth."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from host_sdk import Robot
from host_sdk.geometry import robot_geometry


@dataclass(frozen=True, slots=True)
class CylinderAhead:
    x_m: float
    """The cylinder's centre (the robot starts at x 1.0, y 1.5, facing +x)."""
    y_m: float = 1.5
    radius_m: float = 0.15

    def toml(self) -> str:
        return f"""
[world]
name = "cylinder_ahead"
size_m = [5.0, 3.0]

[start]
x_m = 1.0
y_m = 1.5
theta_deg = 0.0

[[cylinders]]
center = [{self.x_m}, {self.y_m}]
radius_m = {self.radius_m}
height_m = 0.5
"""

    def write(self, folder: Path) -> Path:
        path = folder / "cylinder_ahead.toml"
        path.write_text(self.toml())
        return path

    def gap(self, robot: Robot) -> float:
        """Between the robot's body and the cylinder, from the emulator's ground truth."""
        truth, body = robot.emulator.truth.world, robot_geometry(robot).footprint
        cx = truth.x_m + body.x_m * math.cos(truth.theta_rad)
        cy = truth.y_m + body.x_m * math.sin(truth.theta_rad)
        return math.hypot(self.x_m - cx, self.y_m - cy) - self.radius_m - body.radius_m
