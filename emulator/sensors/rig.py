"""Put an emulated robot in a world and give it sensors.

    emu = Emulator("picar", seed=3)
    rig = attach(emu, world="random:3", lidar="ydlidar-f4", camera=True)
    emu.advance(1.0)
    rig.devices["lidar"].host_write(b"\\xa5\\x60", emu.now_us)     # what a driver's port would send
    data = rig.devices["lidar"].host_read(emu.now_us)

Any device can go on any profile: it sits where the profile carries that kind of sensor
(protocol/spec/sensors.toml; a robot file's [sensors.*]), or, when the robot has none of that
kind, at a default spot (a lidar on top of the pose point, an IMU at it, a camera at the front of
the footprint). Every device is updated every BATCH_US of virtual time (after the physics step),
producing what fell due since. A device whose update raises is marked failed and stops sending
(`SensorRig.failed`; a `sensor_fail` record in the emulator's log): the board and the other devices
carry on.
"""

from __future__ import annotations

from pathlib import Path

from emulator.clock import PRIORITY_OTHER
from emulator.device import Emulator
from emulator.errors import EmulatorValueError
from emulator.sensors.camera import CameraOptions
from emulator.sensors.mjpeg import CameraDevice
from emulator.sensors.rplidar import RPLidarA1
from emulator.sensors.serial import SerialSensor
from emulator.sensors.wit import JY901
from emulator.sensors.ydlidar import YDLidarF4
from emulator.world.scenario import load_world
from emulator.world.scene import Scene
from emulator.world.world import World
from protocol.generated.profiles import ROBOT_SENSORS
from protocol.sensors import DEVICES, CameraSpec, ImuSpec, LidarSpec, Mount, device

BATCH_US = 5000
LIDARS = tuple(n for n, d in DEVICES.items() if d.kind == "lidar")
IMUS = tuple(n for n, d in DEVICES.items() if d.kind == "imu")
CAMERAS = tuple(n for n, d in DEVICES.items() if d.kind == "camera")
Device = SerialSensor | CameraDevice


class SensorRig:
    """The world and the devices attached to one emulator."""

    def __init__(self, emu: Emulator, world: World) -> None:
        self.emu = emu
        self.world = world
        self.devices: dict[str, Device] = {}
        self.failed: dict[str, str] = {}
        """Devices (by kind) whose update raised, and the exception: they send nothing more."""
        emu.world = world
        emu.sensors = self
        emu.clock.call_at(emu.now_us + BATCH_US, self._tick, PRIORITY_OTHER)

    def mount_for(self, kind: str, device_name: str) -> Mount:
        return self.emu.profile.sensors.placed(kind, device_name)

    def _motion(self) -> tuple[float, float, float]:
        v = self.emu.plant.vehicle
        return self.world.robot_pose(self.emu.plant)[2], v.v_m_s, v.wz_rad_s

    def _yaw_rate(self) -> float:
        return self.emu.plant.vehicle.wz_rad_s

    def add(self, kind: str, name: str, **options: object) -> Device:
        spec = device(name, kind)
        mount = self.mount_for(kind, name)
        emu = self.emu
        dev: Device
        if isinstance(spec, LidarSpec):
            cls = RPLidarA1 if spec.protocol == "rplidar" else YDLidarF4
            dev = cls(spec, mount, emu.streams, emu._log)
            scan_hz = options.get("scan_hz")
            if isinstance(scan_hz, int | float):
                if not spec.scan_hz_min <= scan_hz <= spec.scan_hz_max:
                    raise EmulatorValueError("lidar scan_hz", scan_hz, f"{spec.scan_hz_min:g}..{spec.scan_hz_max:g} Hz")
                dev.model.scan_hz = float(scan_hz)
        elif isinstance(spec, ImuSpec):
            dev = JY901(spec, mount, emu.streams, emu._log, self._motion)
        else:
            assert isinstance(spec, CameraSpec)
            opts = options.get("camera_options")
            dev = CameraDevice(
                spec,
                mount,
                opts if isinstance(opts, CameraOptions) else CameraOptions(),
                emu.streams,
                self._yaw_rate,
                realtime_us=lambda: emu.realtime_us,
            )
        self.devices[kind] = dev
        return dev

    def _tick(self) -> None:
        now = self.emu.now_us
        scene = self.world.scene
        scene.set_time(now / 1e6)  # the target where it is now (the world moves it lazily)
        for kind, dev in self.devices.items():
            if kind in self.failed:
                continue
            try:
                dev.update(scene, now, self.world.pose_at)
            except Exception as exc:  # a device's bug must not stop the clock it shares
                self._fail(kind, dev, now, exc)
        self.emu.clock.call_at(now + BATCH_US, self._tick, PRIORITY_OTHER)

    def _fail(self, kind: str, dev: Device, now_us: int, exc: Exception) -> None:
        """A device whose update raised goes dead, as a real one would: it is updated no more, its
        line is cut (nothing it still had queued arrives), and the emulator's log says why. The
        board and the other devices carry on: they share the clock the exception would have
        stopped."""
        self.failed[kind] = f"{type(exc).__name__}: {exc}"
        if isinstance(dev, SerialSensor):
            dev.tx.set_cut(True, now_us)
        self.emu._log(now_us, "sensor_fail", f"{kind} {self.failed[kind]}")


def mount_on(profile: str, kind: str, device_name: str) -> Mount:
    """Where `profile` carries a device of `kind` (sensors.toml), else that kind's default spot."""
    return ROBOT_SENSORS[profile].placed(kind, device_name)


def camera_options(
    size: str | None = None, *, look: str = "plain", distractors: int | None = None, **extra: float
) -> CameraOptions:
    """CameraOptions from "WIDTHxHEIGHT" (one of the camera's sizes), in `look`."""
    spec = DEVICES["pi-camera-v2"]
    assert isinstance(spec, CameraSpec)
    width, height = spec.width, spec.height
    if size:
        try:
            width, height = (int(v) for v in size.lower().split("x"))
        except ValueError:
            raise EmulatorValueError("camera size", size, "WIDTHxHEIGHT, e.g. 320x240") from None
        if (width, height) not in spec.sizes:
            raise EmulatorValueError("camera size", size, " or ".join(f"{w}x{h}" for w, h in spec.sizes))
    return CameraOptions(width=width, height=height, look=look, distractors=distractors, **extra)


def attach(
    emu: Emulator,
    world: str | Path | Scene = "random:0",
    *,
    lidar: str | None = None,
    imu: str | None = None,
    camera: bool | CameraOptions = False,
    lidar_hz: float | None = None,
) -> SensorRig:
    """Give `emu` a world (a Scene, a scenario file or random:SEED) and the named devices."""
    if getattr(emu, "sensors", None) is not None:
        raise EmulatorValueError("emulator", emu.profile.name, "an emulator without sensors (attach once)")
    scene = world if isinstance(world, Scene) else load_world(world)
    for kind, name in (("lidar", lidar), ("imu", imu)):
        if name:
            device(name, kind)  # SensorSpecError (a ValueError) names the choices
    rig = SensorRig(emu, World(scene, emu.profile.name, emu.profile.sensors))
    if lidar:
        rig.add("lidar", lidar, scan_hz=lidar_hz)
    if imu:
        rig.add("imu", imu)
    if camera:
        opts = camera if isinstance(camera, CameraOptions) else CameraOptions()
        rig.add("camera", CAMERAS[0], camera_options=opts)
    return rig
