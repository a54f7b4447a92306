"""The `emu://` URL: an in-process emulator as the SDK's transport (registered as a plugin).

The SDK finds this module through the `roverlink.transports` entry point `emu` and calls
`open_url(url, baud)`; nothing here imports the SDK (it adapts the returned object).

    emu://                                  the diff-drive car (diffdrive-tb6612), wall-clock paced
    emu://picar?seed=3                      the Ackermann PiCar, random streams seeded with 3
    emu://diffdrive-bts7960?clock=virtual   virtual time: read() moves the emulator's clock
    emu://diffdrive-tb6612?faults=bitflip%3D1e-4,cut%402-2.5&dtr=1
    emu://?robot=my_robot.toml&clock=virtual  the robot a robot file describes (emulator.robot_file)

Query parameters (all optional):

| name | values | default | meaning |
|---|---|---|---|
| robot | path | none | a robot file (docs/robot-file.md) in place of the profile name |
| seed | integer | 0 | seed of every random stream in the emulator |
| faults | fault spec (emulator.faults) | none | injected faults, URL-encoded (`=` as `%3D`, `@` as `%40`) |
| clock | real, virtual | real | real: the emulator keeps pace with wall time; virtual: only `read()` moves time |
| speed | number > 0 | 1 | real clock only: emulated seconds per wall second |
| dtr | 0, 1 | 0 | 1: opening resets the board through DTR, as opening a real Arduino's port does |
| latency_us | integer | 1000 | one-way latency of the emulated USB-serial adapter |
| drift_ppm | number | 0 | the MCU crystal's error |
| eeprom | blank, saved | saved | a board whose defaults were saved, or a new one (blank: it warns in a LOG) |
| stand | 0, 1 | 0 | 1: the robot starts on a stand (wheels in the air); `Emulator.set_stand()` changes it |
| physical | nominal, miscalibrated | nominal | how the robot is really built (emulator.physical) |
| cpr_scale, wheel_scale, track_scale, steering_ratio | number | 1 | true / configured cpr, wheel, track, linkage |
| motor_flip, encoder_flip | 0..3 | 0 | wheel bit mask: mounted the other way than motor_invert / encoder_invert say |
| steering_trim_deg | number | 0 | servo angle past the configured centre at which the wheels point straight |
| world | path, random:SEED, empty | random:`seed` (IMU alone: empty) | surroundings (sensors.md); alone: no sensors |
| lidar | rplidar-a1, ydlidar-f4 | none | attach a lidar (its `emudev://` URL is in `endpoints["lidar"]`) |
| lidar_hz | number | the device's | the lidar's scan rate |
| imu | jy901 | none | attach the IMU (`endpoints["imu"]`) |
| camera | 0, 1, WIDTHxHEIGHT | 0 | attach the camera (`endpoints["camera"]`: an MJPEG byte stream; 1 = 320x240) |
| look | plain, photo | plain | how the camera renders (docs/emulator.md, "The camera's looks"); needs `camera` |
| distractors | 0..8 | 0..2 by world | photo look: cylinders of the world painted like the target; needs `camera` |

With any of world, lidar, lidar_hz, imu or camera, `transport.endpoints` maps `lidar`, `imu`,
`camera` (and `target`, the world's target as a photo for the tracker, with a camera) to the URLs
the SDK's sensor drivers open (`host_sdk.sensors`), and `truth.world` has the robot's pose in the world, the
target and every collision.
"""

from __future__ import annotations

import contextlib
import math
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from urllib.parse import parse_qs, quote, unquote, urlsplit

from emulator.device import Emulator
from emulator.errors import EmulatorError, EmulatorValueError
from emulator.physical import FIELD_NAMES, NOMINAL, Physical, physical_from
from emulator.robot_file import profile_from_file
from emulator.transport.devices import SENSOR_PARAMS, SensorOptions, register, sensor_options, unregister


class LinkClosedError(EmulatorError, ConnectionError):
    """A read or write on a closed emulator transport."""


DEFAULT_PROFILE = "diffdrive-tb6612"
STEP_US = 500
"""Virtual clock: how far one step of `read()` moves time while waiting for bytes."""
_PARAMS = (
    "robot",
    "seed",
    "faults",
    "clock",
    "speed",
    "dtr",
    "latency_us",
    "drift_ppm",
    "eeprom",
    "stand",
    "physical",
    *FIELD_NAMES,
    *SENSOR_PARAMS,
)


@dataclass(frozen=True, slots=True)
class EmulatorOptions:
    """What an `emu://` URL asks for."""

    profile: str = DEFAULT_PROFILE
    robot: str = ""
    """A robot file's path (then `profile` is unused)."""
    seed: int = 0
    faults: str = ""
    clock: str = "real"
    speed: float = 1.0
    dtr: bool = False
    latency_us: int = 1000
    drift_ppm: float = 0.0
    eeprom: str = "saved"
    sensors: SensorOptions | None = None
    stand: bool = False
    physical: Physical = NOMINAL


def parse_emu_url(url: str) -> EmulatorOptions:
    """Options of an `emu://PROFILE?k=v&...` URL; EmulatorValueError (a ValueError) names a bad parameter."""
    parts = urlsplit(url)
    if parts.scheme != "emu":
        raise EmulatorValueError("url", url, "an emu://PROFILE[?options] URL")
    profile = unquote(parts.netloc or parts.path.strip("/"))
    query = parse_qs(parts.query, keep_blank_values=True)
    for key, values in query.items():
        if key not in _PARAMS:
            raise EmulatorValueError(f"url parameter {key!r}", values[-1], f"a known parameter: {', '.join(_PARAMS)}")

    def one(key: str) -> str | None:
        values = query.get(key)
        return values[-1] if values else None

    robot = one("robot")
    if robot is not None and (profile or not robot):
        raise EmulatorValueError("url parameter robot", robot, "a robot file's path, in place of a profile name")

    def number(key: str, kind: type[int] | type[float], default: float, lo: float, hi: float) -> float:
        text = one(key)
        if text is None:
            return default
        what = f"an integer in {int(lo)}..{int(hi)}" if kind is int else f"a number in {lo:g}..{hi:g}"
        try:
            value = kind(text)
        except ValueError:
            raise EmulatorValueError(f"url parameter {key}", text, what) from None
        if not (math.isfinite(value) and lo <= value <= hi):
            raise EmulatorValueError(f"url parameter {key}", text, what)
        return value

    clock = one("clock") or "real"
    if clock not in ("real", "virtual"):
        raise EmulatorValueError("url parameter clock", clock, "real or virtual")
    flags: dict[str, bool] = {}
    for key in ("dtr", "stand"):
        flag = one(key) or "0"
        if flag not in ("0", "1", "true", "false"):
            raise EmulatorValueError(f"url parameter {key}", flag, "0 or 1")
        flags[key] = flag in ("1", "true")
    overrides = {key: value for key in FIELD_NAMES if (value := one(key)) is not None}
    physical = physical_from(one("physical"), overrides)
    eeprom = one("eeprom") or "saved"
    if eeprom not in ("blank", "saved"):
        raise EmulatorValueError("url parameter eeprom", eeprom, "blank or saved")
    return EmulatorOptions(
        profile=profile or DEFAULT_PROFILE,
        robot=robot or "",
        seed=int(number("seed", int, 0, 0, 2**63)),
        faults=one("faults") or "",
        clock=clock,
        speed=number("speed", float, 1.0, 0.01, 1000.0),
        dtr=flags["dtr"],
        latency_us=int(number("latency_us", int, 1000, 0, 1_000_000)),
        drift_ppm=number("drift_ppm", float, 0.0, -10_000, 10_000),
        eeprom=eeprom,
        sensors=sensor_options({k: one(k) for k in SENSOR_PARAMS}),
        stand=flags["stand"],
        physical=physical,
    )


class EmulatorTransport:
    """The host's end of an in-process emulator's serial line.

    With `clock="virtual"`, `read(timeout_s)` runs the emulator forward (at most `timeout_s` of
    virtual time, less if bytes arrive) and `clock()` is the emulator's time: deterministic, and
    no thread is needed. With `clock="real"` the emulator is advanced to match wall time on every
    call, so it behaves like a board on a cable; `lock` serialises access (use
    `with transport.locked() as emu:` to inspect or fault it from another thread).
    """

    def __init__(self, emulator: Emulator, *, clock: str = "virtual", speed: float = 1.0, url: str = "") -> None:
        if clock not in ("real", "virtual"):
            raise EmulatorValueError("clock", clock, "'real' or 'virtual'")
        self.emulator = emulator
        self.device = emulator
        robot_file = emulator.profile.robot_file
        self.robot_file = robot_file
        """The robot file the emulated robot was built from (`robot=`), else None."""
        self.profile = emulator.profile.name if robot_file is None else None
        where = f"?robot={quote(robot_file)}&" if robot_file is not None else f"{emulator.profile.name}?"
        self.url = url or f"emu://{where}seed={emulator.seed}&clock={clock}"
        self.virtual = clock == "virtual"
        self.speed = speed
        self.lock = threading.RLock()
        self._wall0 = time.monotonic()
        self._virtual0_us = emulator.now_us
        if not self.virtual:
            emulator.realtime_us = self._wall_us
        self._closed = False
        self.endpoints: dict[str, str] = {}
        """URLs of the attached sensors (`emudev://...`) by kind: lidar, imu, camera."""

    @classmethod
    def from_url(cls, url: str, baud: int = 115200) -> EmulatorTransport:
        """The emulator an `emu://` URL describes; EmulatorError (e.g. an unknown profile) or
        RobotFileError (a robot file's problems) if it cannot start."""
        options = parse_emu_url(url)
        emu = Emulator(
            profile_from_file(options.robot) if options.robot else options.profile,
            seed=options.seed,
            faults=options.faults or None,
            baud=baud,
            latency_us=options.latency_us,
            drift_ppm=options.drift_ppm,
            eeprom=options.eeprom,
            physical=options.physical,
            stand=options.stand,
        )
        if options.dtr:
            emu.dtr_reset()
        transport = cls(emu, clock=options.clock, speed=options.speed, url=url)
        if options.sensors is not None:
            options.sensors.attach(emu, seed=options.seed)
            transport.endpoints = register(transport)
        return transport

    def clock(self) -> float:
        if self.virtual:
            return self.emulator.now_us / 1e6
        return time.monotonic()

    def _wall_us(self) -> int:
        """The emulated time that matches the wall clock now."""
        return self._virtual0_us + int((time.monotonic() - self._wall0) * self.speed * 1e6)

    def _catch_up(self) -> None:
        target = self._wall_us()
        if target > self.emulator.now_us:
            self.emulator.advance_to_us(target)

    def read(self, timeout_s: float) -> bytes:
        return self.read_from(self.emulator.host_read, timeout_s)

    def read_from(self, source: Callable[[], bytes], timeout_s: float) -> bytes:
        """What `source()` yields, waiting up to `timeout_s` (virtual clock: running the emulator)
        for the first byte: the board's line, or an attached sensor's."""
        self._check_open()
        emu = self.emulator
        if self.virtual:
            end = emu.now_us + max(0, round(timeout_s * 1e6))
            while True:
                data = source()
                if data or emu.now_us >= end:
                    return data
                emu.advance_to_us(min(end, emu.now_us + STEP_US))
        deadline = time.monotonic() + max(0.0, timeout_s)
        while True:
            with self.lock:
                self._catch_up()
                data = source()
            left = deadline - time.monotonic()
            if data or left <= 0:
                return data
            time.sleep(min(0.001, left))

    def write(self, data: bytes) -> None:
        self._check_open()
        with self.lock:
            if not self.virtual:
                self._catch_up()
            self.emulator.host_write(data)

    @contextlib.contextmanager
    def locked(self) -> Iterator[Emulator]:
        """The emulator, held still (real clock) while the block runs."""
        with self.lock:
            if not self.virtual and not self._closed:
                self._catch_up()
            yield self.emulator

    def _check_open(self) -> None:
        if self._closed:
            raise LinkClosedError(f"{self.url} is closed")

    def close(self) -> None:
        self._closed = True
        unregister(self)

    def __enter__(self) -> EmulatorTransport:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def open_url(url: str, baud: int = 115200) -> EmulatorTransport:
    """The `roverlink.transports` entry point for `emu://`."""
    return EmulatorTransport.from_url(url, baud)
