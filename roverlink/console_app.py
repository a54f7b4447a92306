"""`roverlink console` put together: a robot (or the emulator on the wall clock), its sensors, the
web console (host_sdk.console) and the control loop that runs the console's pilot. The robot is
supervised (host_sdk.supervisor): no failure of the board, the link or a sensor ends the run; a
lost port is opened again by itself."""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from host_sdk import Robot, RobotDescription
from host_sdk.autonomy import ControlLoop
from host_sdk.console import Console
from host_sdk.sensors import CameraSource, Jy901, Lidar
from host_sdk.supervisor import Supervisor
from roverlink.follow import emulated
from roverlink.follow.app import RobotPorts, geometry_for
from roverlink.interactive import warn_mismatches
from roverlink.sensors.options import open_imu, open_lidar

EMULATED_LOST_AFTER_S = 1.5
"""How long the in-process emulator's FEEDBACK may pause before its link counts as lost."""


@dataclass(frozen=True, slots=True)
class ConsoleSettings:
    host: str = "127.0.0.1"
    port: int = 8080
    token: str | None = None
    max_speed_m_s: float = 0.45
    target_height_m: float | None = None
    follow_gap_m: float | None = None
    autonomous: bool = False
    """Following goes on with no browser keeping it alive (`--autonomous`)."""
    watchdog_s: float | None = None
    """A robot's watchdog to ask for (default the firmware's); the emulator's is `start_emulated`'s."""
    lost_after_s: float | None = None
    """A robot's FEEDBACK silent this long means its link is lost (default the supervisor's)."""


@dataclass
class ConsoleRun:
    """A running console: the robot, its sensors, the console and the loop (`run` drives it)."""

    supervisor: Supervisor
    console: Console
    loop: ControlLoop
    devices: list[Lidar | CameraSource | Jy901]
    emulated: emulated.EmulatedRobot | None = None
    stopped: threading.Event = field(default_factory=threading.Event)
    _running: threading.Event = field(default_factory=threading.Event)
    _done: threading.Event = field(default_factory=threading.Event)

    @property
    def robot(self) -> Robot:
        """The robot now (another object once a lost port was opened again)."""
        return self.supervisor.robot

    def run(self, duration_s: float | None = None, on_step: Callable[[], None] | None = None) -> None:
        """Run the loop until `stopped` is set (or `duration_s` of the robot's time has passed)."""
        loop = self.loop
        self._running.set()
        try:
            with loop:
                while not self.stopped.is_set():
                    if duration_s is not None and self.supervisor.now() - loop.started_s >= duration_s:
                        break
                    loop.step()
                    self.console.pilot.health = self.sensor_health()
                    if on_step is not None:
                        on_step()
                    loop.wait()
        finally:
            self._done.set()

    def sensor_health(self) -> dict[str, int | str]:
        """The sensors' error counts, and why one stopped being read, for the page's status panel."""
        health: dict[str, int | str] = {}
        for device in self.devices:
            if isinstance(device, Lidar):
                health["lidar errors"] = device.counters.framing_errors + device.counters.checksum_errors
            elif isinstance(device, Jy901):
                health["IMU errors"] = device.counters.checksum_errors
            else:
                health["camera frames dropped"] = device.dropped
        for name, why in self.loop.sensor_errors.items():
            health[f"{name} stopped"] = why
        return health

    def close(self) -> None:
        """Stop the loop (it stops the robot on its way out), then close everything."""
        self.stopped.set()
        if self._running.is_set():  # run() in another thread: let it stop the robot before the port closes
            self._done.wait(timeout=2.0 + 3 * self.loop.period_s)
        self.console.close()
        for device in self.devices:
            device.close()
        self.supervisor.close()


def _assemble(
    sup: Supervisor,
    which: str | RobotDescription,
    settings: ConsoleSettings,
    *,
    lidar: Lidar,
    camera: CameraSource,
    imu: Jy901 | None,
    em: emulated.EmulatedRobot | None,
) -> ConsoleRun:
    geo = geometry_for(sup.robot, which)
    console = Console(
        sup,
        geo,
        host=settings.host,
        port=settings.port,
        token=settings.token,
        target_height_m=settings.target_height_m,
        follow_gap_m=settings.follow_gap_m,
        max_speed_m_s=settings.max_speed_m_s,
        autonomous=settings.autonomous,
    )
    # Only the page arms the robot: not at the start, not after a failsafe or a reset.
    loop = ControlLoop(sup, console.pilot, lidar=lidar, camera=camera, imu=imu, arm=False, rearm=False)
    devices: list[Lidar | CameraSource | Jy901] = [d for d in (lidar, camera, imu) if d is not None]
    return ConsoleRun(sup, console, loop, devices, em)


def start_emulated(
    which: str | RobotDescription,
    world: str | Path,
    settings: ConsoleSettings,
    *,
    seed: int = 0,
    camera_fps: float = 15.0,
    imu: bool = True,
    camera_look: str = "plain",
    watchdog_s: float | None = None,
) -> ConsoleRun:
    """The console on an emulated robot in `world`, on the wall clock; listening once this returns.
    Only the user arms it (no re-arming after a failsafe); `watchdog_s`: the board's (default the
    firmware's), which is also how long a command from the page lives."""
    em = emulated.start(
        which,
        world,
        seed=seed,
        camera_fps=camera_fps,
        imu=imu,
        camera_look=camera_look,
        clock="real",
        auto_rearm=False,
        watchdog_s=watchdog_s,
    )
    try:
        lidar = Lidar.open(em.endpoints["lidar"], em.lidar_model)
        camera = CameraSource(em.endpoints["camera"])
        imu_port = Jy901.open(em.endpoints["imu"]) if imu else None
        # The emulator shares this process (and its interpreter lock) with the console on the wall
        # clock: its FEEDBACK comes in bursts on a busy machine, so a longer silence means a lost link.
        sup = Supervisor(em.robot, lost_after_s=EMULATED_LOST_AFTER_S)
        run = _assemble(sup, which, settings, lidar=lidar, camera=camera, imu=imu_port, em=em)
        if settings.target_height_m is None:
            run.console.pilot.target_height_m = em.template.height_m
        run.console.start()
    except BaseException:
        em.robot.close()
        raise
    return run


def start_robot(ports: RobotPorts, which: str | RobotDescription, settings: ConsoleSettings) -> ConsoleRun:
    """The console on a real robot; listening once this returns."""
    desc, name = (which, None) if isinstance(which, RobotDescription) else (None, which)
    watchdog = emulated.watchdog_for(ports.url, settings.watchdog_s)
    sup = Supervisor.connect(
        ports.url,
        profile=name,
        robot=desc,
        baud=ports.baud,
        allow_mismatch=ports.allow_mismatch,
        clamp=True,
        watchdog_s=watchdog,
        lost_after_s=settings.lost_after_s,
    )
    robot = sup.robot
    warn_mismatches(robot)
    opened: list[Lidar | CameraSource | Jy901] = []
    try:
        geo = geometry_for(robot, which)
        devices = ports.devices(robot, which)
        assert devices.lidar is not None and devices.camera is not None  # ports.devices required them
        camera = CameraSource(devices.camera, width=geo.camera.width, height=geo.camera.height)
        opened.append(camera)
        lidar = open_lidar(devices)
        opened.append(lidar)
        imu = open_imu(devices)
        run = _assemble(sup, which, settings, lidar=lidar, camera=camera, imu=imu, em=None)
        run.console.start()
    except BaseException:
        for device in opened:
            device.close()
        sup.close()
        raise
    return run
