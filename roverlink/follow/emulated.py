"""`roverlink follow` on the emulator: a robot in a world with a lidar, a camera and an IMU, on the
virtual clock, and the ground truth the metrics are judged by.

The robot code is the same as on a real robot: the SDK connects to the board's transport and the
drivers open the sensors' `emudev://` endpoints. Only two things come from the emulator: the
target's look (rendered once as the tracker's template, as a user would give a photo of it) and the
truth (pose, target, collisions) for the metrics.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from emulator import Emulator
from emulator.robot_file import profile_from_file
from emulator.sensors import attach
from emulator.sensors.camera import CameraOptions
from emulator.sensors.target import TargetTemplate, render_target
from emulator.transport.devices import register
from emulator.transport.inprocess import EmulatorTransport
from emulator.world.raycast import nearest
from emulator.world.scene import Scene
from host_sdk import Robot, RobotDescription
from host_sdk.transport.plugins import PluginTransport
from protocol.generated.constants import WATCHDOG_DEFAULT_MS
from protocol.sensors import DEVICES, CameraSpec, Mount
from roverlink.follow.metrics import TruthSample

SHARED_WATCHDOG_S = 1.0
"""The watchdog asked for when the emulator shares this process on the wall clock: its work, the
robot program's and a browser's share the machine, and a busy one misses the firmware's 250 ms
every few seconds (docs/console.md, "On the emulator")."""


def watchdog_for(url: str | None, asked_s: float | None) -> float:
    """The watchdog to connect with: the one asked for, else SHARED_WATCHDOG_S for an in-process
    emulator on the wall clock (no URL, or an emu:// URL without clock=virtual), else the firmware's."""
    if asked_s is not None:
        return asked_s
    shared = url is None or (url.startswith("emu://") and "clock=virtual" not in url)
    return SHARED_WATCHDOG_S if shared else WATCHDOG_DEFAULT_MS / 1000


RUN_INTO_M_S = 0.02
"""A contact in which the robot moved towards the contact point no faster than this was not driven
into: the robot stood (or crept, or moved away) and the target walked into it."""
LIDAR_FOR = {"picar": "ydlidar-f4", "diffdrive-bts7960": "rplidar-a1", "diffdrive-tb6612": "rplidar-a1"}
"""The lidar each profile carries (the TB6612 car gets the SLAM robot's A1 on top)."""


@dataclass
class EmulatedRobot:
    robot: Robot
    emulator: Emulator
    scene: Scene
    endpoints: dict[str, str]
    lidar_model: str
    template: TargetTemplate
    truth: TruthProbe


def lidar_for(robot: str | RobotDescription) -> str:
    """The lidar model a reference robot carries, or the one its robot file names."""
    if isinstance(robot, RobotDescription):
        return robot.sensors().placed("lidar").device
    return LIDAR_FOR.get(robot, "rplidar-a1")


def start(
    profile: str | RobotDescription,
    world: str | Path,
    *,
    seed: int = 0,
    camera_fps: float = 15.0,
    imu: bool = True,
    faults: str | None = None,
    camera_look: str = "plain",
    clock: str = "virtual",
    auto_rearm: bool = False,
    watchdog_s: float | None = None,
) -> EmulatedRobot:
    """Connect to an emulated `profile` (a reference robot, or the robot a robot file describes:
    connected with the file, as on a real robot) in `world` with its sensors attached; on the virtual
    clock (as fast as the CPU allows) or the "real" one (wall time, for a person watching).
    `auto_rearm` and `watchdog_s` (default: the firmware's) are passed to `Robot.connect`."""
    desc = profile if isinstance(profile, RobotDescription) else None
    model = profile_from_file(desc.path) if desc is not None else profile
    assert not isinstance(model, RobotDescription)
    emu = Emulator(model, seed=seed, faults=faults, eeprom="saved")
    cam = desc.camera if desc is not None else None
    options = CameraOptions(fps=camera_fps, look=camera_look)
    if cam is not None:
        options = replace(options, width=cam.width, height=cam.height)
    rig = attach(emu, world, lidar=lidar_for(profile), imu="jy901" if imu else None, camera=options)
    transport = EmulatorTransport(emu, clock=clock)
    transport.endpoints = register(transport)
    robot = Robot.connect(
        transport.url,
        profile=None if desc else emu.profile.name,
        robot=desc,
        transport=PluginTransport(transport),
        clamp=True,
        auto_rearm=auto_rearm,
        watchdog_s=WATCHDOG_DEFAULT_MS / 1000 if watchdog_s is None else watchdog_s,
    )
    cm = rig.mount_for("camera", "pi-camera-v2")
    spec = DEVICES["pi-camera-v2"]
    assert isinstance(spec, CameraSpec)
    scene = rig.world.scene
    template = render_target(scene, cm, look=camera_look)
    return EmulatedRobot(
        robot, emu, scene, dict(transport.endpoints), lidar_for(profile), template, TruthProbe(emu, cm, spec.hfov_deg)
    )


class TruthProbe:
    """The emulator's ground truth as the metrics want it."""

    def __init__(self, emu: Emulator, camera_mount: Mount, hfov_deg: float) -> None:
        self.emu = emu
        self.body = emu.profile.sensors
        self.mount = camera_mount
        self.half_fov = math.radians(hfov_deg) / 2

    def sample(self) -> TruthSample:
        emu = self.emu
        world = emu.world
        assert world is not None
        x, y, th = world.robot_pose(emu.plant)
        scene = world.scene
        names = tuple(c.obstacle for c in world.collisions)
        run_into = sum(1 for c in world.collisions if c.closing_m_s <= RUN_INTO_M_S)
        distance = emu.plant.vehicle.distance_m
        target = scene.target
        if target is None:
            return TruthSample(False, math.inf, names, distance, run_into)
        tx, ty = float(scene.circles[-1, 0]), float(scene.circles[-1, 1])
        fx, fy = world.footprint(x, y, th)
        gap = math.hypot(tx - fx, ty - fy) - self.body.footprint_radius_m - target.radius_m
        m = self.mount
        cx, cy = x + math.cos(th) * m.x_m - math.sin(th) * m.y_m, y + math.sin(th) * m.x_m + math.cos(th) * m.y_m
        bearing = math.remainder(math.atan2(ty - cy, tx - cx) - th - m.yaw_rad, 2 * math.pi)
        in_view = abs(bearing) <= self.half_fov
        if in_view:
            d = math.hypot(tx - cx, ty - cy)
            direction = np.array([[(tx - cx) / d, (ty - cy) / d]])
            _, shape, _ = nearest(scene, np.array([[cx, cy]]), direction)
            in_view = int(shape[0]) == scene.target_index
        return TruthSample(in_view, gap, names, distance, run_into)
