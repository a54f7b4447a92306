"""Putting a follow run together: the pilot for a robot, then a run on a real robot or the emulator."""

from __future__ import annotations

import argparse
import contextlib
import importlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from host_sdk import Robot, RobotDescription
from host_sdk.autonomy import FollowPilot, Pilot, follow_gap
from host_sdk.errors import CommandRangeError
from host_sdk.geometry import RobotGeometry, robot_geometry
from host_sdk.perception import Tracker
from host_sdk.perception.class_tracker import ClassTracker, FrameTracker
from host_sdk.recording.follow import FollowSource
from host_sdk.sensors import CameraSource, Jy901, Lidar
from host_sdk.supervisor import Supervisor
from roverlink.follow import emulated
from roverlink.follow.baseline import PiCarBaseline
from roverlink.follow.metrics import FollowMetrics
from roverlink.follow.run import Progress, run_follow
from roverlink.interactive import announce_live_view, warn_mismatches
from roverlink.sensors.options import SensorChoice, open_imu, open_lidar, require_sensors, sensors_for

PILOTS = ("roverlink", "picar-2018")
LIDAR_FOR = emulated.LIDAR_FOR


@dataclass(frozen=True, slots=True)
class RecordTo:
    """Record the run (host_sdk.recording): an MCAP file and/or the live Foxglove view."""

    mcap_path: Path | None = None
    serve: bool = False
    host: str = "127.0.0.1"
    port: int = 8765


@contextlib.contextmanager
def recording(robot: Robot, pilot: Pilot, record: RecordTo | None) -> Iterator[Callable[[float], None] | None]:
    """The recorder's poll for the follow loop (None when not recording). The recorder is the shared
    library piece `roverlink record` and `monitor --foxglove` use; the follow run adds its scan, camera
    and behaviour to it (host_sdk.recording.follow.FollowSource)."""
    if record is None:
        yield None
        return
    try:
        library = importlib.import_module("host_sdk.recording")
    except ImportError as exc:
        raise RuntimeError(f"recording needs host_sdk.recording and the foxglove extra ({exc})") from None
    sources = [FollowSource(pilot)] if isinstance(pilot, FollowPilot) else []
    recorder = library.Recorder.attach(
        robot,
        mcap_path=record.mcap_path,
        overwrite=True,
        serve=record.serve,
        host=record.host,
        port=record.port,
        sources=sources,
    )
    if record.serve:
        announce_live_view(recorder)
    try:
        yield lambda _t: recorder.poll()
    finally:
        recorder.close()


@dataclass(frozen=True, slots=True)
class FollowSettings:
    follow_gap_m: float | None = None
    """Gap to keep (footprint to target). Default: 0.5 m for a differential drive, 0.9 m for an
    Ackermann robot, which cannot turn on the spot: from farther back a target that turns moves less
    across the image, and the car has room to drive the arc that keeps it in view."""
    max_speed_m_s: float = 0.45
    target_height_m: float | None = None
    """The tracked region's real height (gives the tracker a range estimate; with `target`, the
    kind's by default: 1.7 m for a person, 0.16 m for a face)."""
    duration_s: float = 60.0
    target: str | None = None
    """"person" or "face": the target is detected (host_sdk.perception.detectors) in place of a
    template or a selected region, and detected again when the tracker has lost it."""
    rearm: bool = False
    """Arm again by itself after a failsafe or a board reset (an opt-in: by default the robot stays
    disarmed, and following with it, once the board has failed safe)."""


def gap_for(settings: FollowSettings, geo: RobotGeometry) -> float:
    return follow_gap(geo) if settings.follow_gap_m is None else settings.follow_gap_m


def make_pilot(kind: str, geo: RobotGeometry, template: NDArray[np.uint8] | None, settings: FollowSettings) -> Pilot:
    """RoverLink's behaviour ("roverlink") or the PiCar team's ("picar-2018") for this robot, following
    what `template` shows or, with `settings.target`, a detected person or face."""
    if kind not in PILOTS:
        raise ValueError(f"pilot {kind!r} is not allowed: one of {', '.join(PILOTS)}")
    tracker: FrameTracker
    if settings.target is not None:
        tracker = ClassTracker(settings.target, geo.camera, height_m=settings.target_height_m)
    elif template is not None:
        tracker = Tracker(template, geo.camera, height_m=settings.target_height_m)
    else:
        raise ValueError("no target: give a template image or a target kind (person or face)")
    if kind == "picar-2018":
        return PiCarBaseline(tracker, geo.camera, geo.lidar_mount, settings.max_speed_m_s)
    return FollowPilot.with_tracker(
        geo, tracker, follow_gap_m=settings.follow_gap_m, max_speed_m_s=settings.max_speed_m_s
    )


def geometry_for(robot: Robot, which: str | RobotDescription) -> RobotGeometry:
    """The pilot's geometry: the reference robot's mounts, or all of it from the robot file."""
    if isinstance(which, RobotDescription):
        return robot_geometry(robot, description=which)
    return robot_geometry(robot, which)


def _metrics(
    pilot: str, which: str | RobotDescription, world: str | None = None, url: str | None = None
) -> FollowMetrics:
    if isinstance(which, RobotDescription):
        return FollowMetrics(pilot, which.name, world=world, url=url, robot_file=which.path)
    return FollowMetrics(pilot, which, world=world, url=url)


def run_emulated(
    profile: str | RobotDescription,
    world: str | Path,
    *,
    pilot: str = "roverlink",
    seed: int = 0,
    camera_fps: float = 15.0,
    imu: bool = True,
    settings: FollowSettings | None = None,
    camera_look: str = "plain",
    progress: Callable[[Progress], None] | None = None,
    record: RecordTo | None = None,
) -> FollowMetrics:
    """One follow run on the emulator (virtual clock); the metrics, with the truth's figures.
    `profile`: a reference robot, or a robot file's description (the emulated robot is the file's)."""
    settings = settings or FollowSettings()
    if settings.target is not None:
        raise ValueError(
            f"target {settings.target!r} needs a camera that sees people (a robot's): the emulated "
            "world's target is a rendered shape, which neither detector is made for"
        )
    em = emulated.start(profile, world, seed=seed, camera_fps=camera_fps, imu=imu, camera_look=camera_look)
    robot = em.robot
    try:
        if settings.target_height_m is None:
            settings = replace(settings, target_height_m=em.template.height_m)
        geo = geometry_for(robot, profile)
        chosen = make_pilot(pilot, geo, em.template.image, settings)
        lidar = Lidar.open(em.endpoints["lidar"], em.lidar_model)
        camera = CameraSource(em.endpoints["camera"])
        imu_port = Jy901.open(em.endpoints["imu"]) if imu else None
        metrics = _metrics(chosen.name, profile, world=str(world))
        with recording(robot, chosen, record) as on_step:
            return run_follow(
                robot,
                lidar,
                camera,
                chosen,
                duration_s=settings.duration_s,
                metrics=metrics,
                follow_gap_m=gap_for(settings, geo),
                imu=imu_port,
                truth=em.truth.sample,
                progress=progress,
                on_step=on_step,
                rearm=settings.rearm,
            )
    finally:
        robot.close()


@dataclass(frozen=True, slots=True)
class RobotPorts:
    url: str
    """The board."""
    lidar: str | None
    """None: an emu:// URL's lidar, else the robot file's [sensors.lidar] port (roverlink.sensors)."""
    camera: str | int | None
    """Any host_sdk.sensors.CameraSource source: picamera2, a V4L2 index or path, jetson-csi, a pipeline, a URL
    (None: an emu:// URL's camera, else the robot file's [sensors.camera] source)."""
    imu: str | None = None
    lidar_model: str | None = None
    """rplidar-a1 or ydlidar-f4 (default: the profile's or the robot file's)."""
    baud: int = 115200
    allow_mismatch: bool = False
    """With a robot file: connect even if the board differs from it (warned about)."""
    imu_baud: int | None = None
    """None: the robot file's [sensors.imu] baud, else the JY901's default."""

    def check(self, which: str | RobotDescription) -> None:
        """Before connecting to a real port: RoverLinkError when neither the options nor the robot
        file give the lidar and the camera (an emu:// URL's own are known once it is connected)."""
        if self.url.startswith("emu://"):
            return
        desc = which if isinstance(which, RobotDescription) else None
        lidar = self.lidar or (desc.lidar.port if desc is not None and desc.lidar is not None else None)
        camera = self.camera or (desc.camera.source if desc is not None and desc.camera is not None else None)
        require_sensors(SensorChoice(lidar=lidar or None, camera=camera or None), ("lidar", "camera"))

    def devices(self, robot: Robot, which: str | RobotDescription) -> SensorChoice:
        """The lidar, camera and IMU to open for the connected `robot`: these ports, else its emu://
        URL's devices, else the robot file's (roverlink.sensors.sensors_for); the lidar and the
        camera are needed (RoverLinkError naming how to give them)."""
        desc = which if isinstance(which, RobotDescription) else None
        choice = sensors_for(
            robot,
            desc,
            lidar=self.lidar,
            lidar_model=self.lidar_model,
            imu=self.imu,
            imu_baud=self.imu_baud,
            camera=self.camera,
        )
        require_sensors(choice, ("lidar", "camera"), self.url)
        if self.lidar_model is None and choice.lidar != robot.transport.endpoints.get("lidar"):
            choice = replace(choice, lidar_model=emulated.lidar_for(which))
        return choice


def robot_ports(args: argparse.Namespace) -> RobotPorts:
    """The board and the sensors `roverlink console` and `roverlink follow` were given (--url, --baud,
    --allow-mismatch and roverlink.sensors' options); what is not given is chosen on connecting."""
    return RobotPorts(
        args.url, args.lidar, args.camera, args.imu, args.lidar_model, args.baud, args.allow_mismatch, args.imu_baud
    )


def run_robot(
    ports: RobotPorts,
    profile: str | RobotDescription,
    *,
    template: NDArray[np.uint8] | None = None,
    select: tuple[float, float, float, float] | None = None,
    pilot: str = "roverlink",
    settings: FollowSettings | None = None,
    progress: Callable[[Progress], None] | None = None,
    record: RecordTo | None = None,
) -> FollowMetrics:
    """Follow on a real robot: the target is a template image, a region `select`ed in the first frame,
    or a person or a face (`settings.target`) the detector picks.
    `profile`: a reference robot, or a robot file's description (compared with the board, its limits
    and gains applied; the geometry, lidar model and footprint are the file's)."""
    settings = settings or FollowSettings()
    given = sum(v is not None for v in (template, select, settings.target))
    if given > 1 or (given == 0 and not ports.url.startswith("emu://")):  # an emu:// robot serves its target
        raise ValueError(
            "give the target as a template image, a region of the first frame or a kind (person or face): one of them"
        )
    desc, name = (profile, None) if isinstance(profile, RobotDescription) else (None, profile)
    sup = Supervisor.connect(
        ports.url,
        profile=name,
        robot=desc,
        baud=ports.baud,
        allow_mismatch=ports.allow_mismatch,
        clamp=True,
        watchdog_s=emulated.watchdog_for(ports.url, None),
    )
    robot = sup.robot
    warn_mismatches(robot)
    camera = lidar = imu = None
    try:
        geo = geometry_for(robot, profile)
        # asked at the size the pilot's camera model has (a device that cannot set it gives its own)
        devices = ports.devices(robot, profile)
        assert devices.lidar is not None and devices.camera is not None  # ports.devices required them
        camera = CameraSource(devices.camera, width=geo.camera.width, height=geo.camera.height)
        if template is None and select is None and settings.target is None:
            template = _emulated_target(robot)
        if select is not None:
            image = camera.read(5.0).image
            x, y, w, h = (round(v) for v in select)
            H, W = image.shape[:2]
            if not (x >= 0 and y >= 0 and w >= 6 and h >= 6 and x + w <= W and y + h <= H):
                where = f"a box inside the camera's {W}x{H} frame, at least 6 pixels a side"
                raise CommandRangeError("--select", ",".join(str(v) for v in (x, y, w, h)), where)
            template = image[y : y + h, x : x + w].copy()
        chosen = make_pilot(pilot, geo, template, settings)
        lidar = open_lidar(devices)
        imu = open_imu(devices)
        metrics = _metrics(chosen.name, profile, url=ports.url)
        with recording(robot, chosen, record) as on_step:
            return run_follow(
                sup,
                lidar,
                camera,
                chosen,
                duration_s=settings.duration_s,
                metrics=metrics,
                follow_gap_m=gap_for(settings, geo),
                imu=imu,
                progress=progress,
                on_step=on_step,
                rearm=settings.rearm,
            )
    finally:
        for device in (lidar, imu, camera):
            if device is not None:
                device.close()
        sup.close()


def _emulated_target(robot: Robot) -> NDArray[np.uint8]:
    """The photo of its world's target an emulated robot with a camera serves (`endpoints["target"]`);
    a real robot has none, so the target must be given."""
    url = robot.transport.endpoints.get("target")
    if url is None:
        raise ValueError("give the target as a template image, a region of the first frame or a kind (person or face)")
    with CameraSource(url) as photo:
        return photo.read(5.0).image
