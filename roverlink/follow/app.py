"""Putting a follow run together: the pilot for a robot, and a whole run on the emulator."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from host_sdk.autonomy import Follower, FollowParams
from host_sdk.kinematics import Ackermann
from host_sdk.perception import AvoidanceParams, CameraModel, Footprint, LidarMount, ScanFilter, Tracker
from host_sdk.sensors import CameraSource, Jy901, Lidar
from roverlink.follow import emulated
from roverlink.follow.metrics import FollowMetrics
from roverlink.follow.pilots import PiCarBaseline, Pilot, RoverLinkPilot
from roverlink.follow.run import Progress, run_follow

PILOTS = ("roverlink", "picar-2018")


@dataclass(frozen=True, slots=True)
class RobotGeometry:
    footprint: Footprint
    camera: CameraModel
    lidar_mount: LidarMount
    min_turn_radius_m: float
    """0: differential drive."""


@dataclass(frozen=True, slots=True)
class FollowSettings:
    follow_gap_m: float = 0.5
    max_speed_m_s: float = 0.45
    target_height_m: float | None = None
    """The tracked region's real height (gives the tracker a range estimate)."""


def make_pilot(kind: str, geometry: RobotGeometry, template: NDArray[np.uint8], settings: FollowSettings) -> Pilot:
    """RoverLink's behaviour ("roverlink") or the PiCar team's ("picar-2018") for this robot."""
    tracker = Tracker(template, geometry.camera, height_m=settings.target_height_m)
    if kind == "picar-2018":
        return PiCarBaseline(tracker, geometry.camera, geometry.lidar_mount, settings.max_speed_m_s)
    if kind != "roverlink":
        raise ValueError(f"pilot {kind!r} is not allowed: one of {', '.join(PILOTS)}")
    follower = Follower(
        geometry.footprint,
        geometry.camera,
        min_turn_radius_m=geometry.min_turn_radius_m,
        avoidance=AvoidanceParams(),
        params=FollowParams(follow_gap_m=settings.follow_gap_m, max_speed_m_s=settings.max_speed_m_s),
    )
    return RoverLinkPilot(ScanFilter(geometry.lidar_mount), tracker, follower)


def run_emulated(profile: str, world: str | Path, *, pilot: str = "roverlink", seed: int = 0, duration_s: float = 60.0,
                 camera_fps: float = 15.0, imu: bool = True, settings: FollowSettings | None = None,
                 progress: Callable[[Progress], None] | None = None) -> FollowMetrics:  # fmt: skip
    """One follow run on the emulator (virtual clock); the metrics, with the truth's figures."""
    settings = settings or FollowSettings()
    em = emulated.start(profile, world, seed=seed, camera_fps=camera_fps, imu=imu)
    robot = em.robot
    try:
        kin = robot.kinematics
        body = em.truth.body
        geometry = RobotGeometry(
            Footprint(body.footprint_radius_m, body.footprint_x_m),
            em.camera,
            em.lidar_mount,
            kin.min_turn_radius_m if isinstance(kin, Ackermann) else 0.0,
        )
        if settings.target_height_m is None:
            settings = FollowSettings(settings.follow_gap_m, settings.max_speed_m_s, em.template.height_m)
        chosen = make_pilot(pilot, geometry, em.template.image, settings)
        lidar = Lidar.open(em.endpoints["lidar"], em.lidar_model)
        camera = CameraSource(em.endpoints["camera"])
        imu_port = Jy901.open(em.endpoints["imu"]) if imu else None
        metrics = FollowMetrics(chosen.name, profile, str(world))
        return run_follow(robot, lidar, camera, chosen, duration_s=duration_s, metrics=metrics,
                          follow_gap_m=settings.follow_gap_m, imu=imu_port, truth=em.truth.sample,
                          progress=progress)  # fmt: skip
    finally:
        robot.close()
