"""The emulated robot's surroundings: a 2D scene, the moving target, collisions and ground truth.

from emulator.world import load_world
scene = load_world("random:3")          # or a scenario file (docs/sensors.md)
"""

from emulator.world.scenario import ScenarioError, load_world, parse_scenario
from emulator.world.scene import Scene, Shape, Target, TargetPath
from emulator.world.world import Collision, World, WorldTruth

__all__ = [
    "Collision",
    "ScenarioError",
    "Scene",
    "Shape",
    "Target",
    "TargetPath",
    "World",
    "WorldTruth",
    "load_world",
    "parse_scenario",
]
