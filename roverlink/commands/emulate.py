"""`roverlink emulate`: serve an emulated robot on a pseudo-terminal (or a TCP socket) in real time.

The first line on stdout is the port to open (e.g. /dev/pts/7, or socket://127.0.0.1:PORT); then
one line per sensor asked for (`--lidar`, `--imu`, `--camera`), whose first word names it and whose
last word is its pty or URL:

    /dev/pts/7
    lidar ydlidar-f4 /dev/pts/8
    imu jy901 /dev/pts/9
    camera pi-camera-v2 http://127.0.0.1:41234/stream.mjpg

The emulator then serves until SIGINT or SIGTERM and exits 0. Progress goes to stderr.
"""

from __future__ import annotations

import argparse
import signal
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any, TextIO

from emulator.device import Emulator
from emulator.errors import BackendError, EmulatorError
from emulator.profiles import PROFILE_NAMES, EmulatorProfile, get_profile
from emulator.robot_file import profile_from_file
from emulator.sensors.camera import LOOKS, MAX_DISTRACTORS
from emulator.sensors.mjpeg import CameraDevice
from emulator.sensors.rig import IMUS, LIDARS
from emulator.sensors.serial import LidarDevice
from emulator.transport.devices import SENSOR_PARAMS, sensor_options
from emulator.transport.http_camera import MjpegServer
from emulator.transport.pty import PtyEndpoint
from emulator.transport.realtime import Endpoint, SerialPeripheral, serve
from emulator.transport.socket import SocketEndpoint
from protocol.robotfile import RobotFileError
from protocol.sensors import SensorSpecError
from roverlink import argtypes, firmware, say


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--backend",
        choices=("python", "simavr", "rp2040"),
        default="python",
        help="python: the firmware model (default); simavr: the example's compiled AVR firmware in simavr "
        "with the same plant and serial line (needs avr-gcc and simavr; it supports every option but --baud "
        "other than 115200, which the firmware's Serial.begin() fixes, and the eeprom@T fault); rp2040: the "
        "Pico firmware in rp2040js (needs arm-none-eabi-gcc, Node.js and `npm ci --prefix tools/rp2040`; "
        '--profile moves the reference robot to the Pico pinout, --robot takes a board = "pico" file; '
        "no --eeprom, --bootloader-ms or eeprom@T: the Pico keeps no configuration)",
    )
    p.add_argument("--profile", default="diffdrive-tb6612", choices=PROFILE_NAMES, help="reference robot to emulate")
    p.add_argument(
        "--robot",
        metavar="FILE",
        help="emulate the robot in this robot file instead of --profile (docs/robot-file.md; simavr: its "
        "firmware is built from the file; both backends: the plant has the file's geometry)",
    )
    p.add_argument(
        "--seed",
        type=argtypes.SEED,
        default=0,
        help="random seed: boot ids (on simavr: the ADC noise and the EEPROM boot counter the firmware mixes "
        "into them), line faults, noise, bootloader garbage (default 0)",
    )
    p.add_argument(
        "--faults",
        default="",
        metavar="SPEC",
        help='faults to inject, e.g. "bitflip=1e-4,drop=1e-4,cut@2.0-3.5,reset@5.0,stall=0@4.0" (docs/emulator.md)',
    )
    p.add_argument(
        "--baud", type=argtypes.BAUD, default=115200, help="line speed in bit/s (default 115200; simavr: 115200 only)"
    )
    p.add_argument(
        "--latency-ms",
        type=argtypes.number(0, 1000, "ms"),
        default=1.0,
        help="one-way adapter latency in ms (default 1)",
    )
    p.add_argument(
        "--drift-ppm",
        type=argtypes.number(-10_000, 10_000, "ppm"),
        default=0.0,
        help="MCU crystal error in ppm (default 0)",
    )
    p.add_argument(
        "--eeprom", choices=("blank", "saved"), default="blank", help="EEPROM at start: blank, or defaults saved"
    )
    p.add_argument(
        "--bootloader-ms",
        type=argtypes.integer(0, 60_000, "ms"),
        default=None,
        help="bootloader time after a DTR or external reset in ms (default: the profile's board)",
    )
    p.add_argument(
        "--socket",
        type=argtypes.integer(0, 65_535),
        default=None,
        metavar="PORT",
        help="serve TCP on 127.0.0.1:PORT instead of a pty (0: any free port)",
    )
    p.add_argument("--no-dtr-reset", action="store_true", help="opening the port does not reset the board")
    p.add_argument(
        "--speed",
        type=argtypes.number(0.01, 1000),
        default=1.0,
        help="virtual seconds per wall second, 0.01..1000 (default 1)",
    )
    p.add_argument("--quiet", action="store_true", help="no progress messages on stderr")
    _add_sensor_arguments(p)


def _add_sensor_arguments(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("world and sensors (docs/sensors.md; python backend)")
    g.add_argument(
        "--world", metavar="FILE|random:SEED|empty", help="the surroundings: a scenario file, random:SEED or empty"
    )
    g.add_argument("--lidar", choices=LIDARS, help="serve a lidar on its own pty")
    g.add_argument(
        "--lidar-hz", type=argtypes.number(0.1, 100), metavar="HZ", help="the lidar's scan rate (default: the device's)"
    )
    g.add_argument("--imu", choices=IMUS, help="serve the IMU on its own pty")
    g.add_argument(
        "--truth",
        type=Path,
        metavar="FILE",
        help="write ground truth to FILE as JSON lines on CLOCK_MONOTONIC: each time the lidar passes its rear, "
        "a LaserScan's ray 0 (to check a host's scan stamps)",
    )
    g.add_argument(
        "--camera", nargs="?", const="320x240", metavar="WxH", help="serve the camera as MJPEG over HTTP (320x240)"
    )
    g.add_argument(
        "--camera-look",
        dest="look",
        choices=LOOKS,
        help="how the camera renders: plain (flat colours, the default) or photo (textures, light, auto-exposure)",
    )
    g.add_argument(
        "--camera-distractors",
        dest="distractors",
        type=argtypes.integer(0, MAX_DISTRACTORS),
        metavar="N",
        help="photo look: paint N of the world's cylinders like the target (default: 0..2 by world)",
    )
    g.add_argument(
        "--camera-port",
        type=argtypes.integer(0, 65_535),
        default=0,
        metavar="PORT",
        help="the camera's TCP port (0: any)",
    )


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register `emulate` on the `roverlink` command's subparsers."""
    p: argparse.ArgumentParser = subparsers.add_parser(
        "emulate", help="serve an emulated robot on a pseudo-terminal", description=__doc__
    )
    add_arguments(p)
    p.set_defaults(func=cmd_emulate)
    return p


def cmd_emulate(args: argparse.Namespace) -> int:
    values = {k: getattr(args, k, None) for k in SENSOR_PARAMS}
    for key in ("lidar_hz", "distractors"):
        values[key] = None if values[key] is None else str(values[key])
    if getattr(args, "backend", "python") != "python":
        if any(values.values()) or args.truth:
            say.error("--world, --lidar, --imu, --camera and --truth need --backend python")
            return 2
        return _cmd_emulate_firmware(args)
    try:
        profile = profile_from_file(args.robot) if args.robot else args.profile
        emu = Emulator(profile, args.seed, **_board_options(args))
        sensors = sensor_options(values)
        if sensors is not None:
            sensors.attach(emu, seed=args.seed)
    except (EmulatorError, SensorSpecError, RobotFileError) as exc:
        say.error(f"{exc}")
        return 2
    if args.truth and not any(
        isinstance(d, LidarDevice) for d in (emu.sensors.devices.values() if emu.sensors else ())
    ):
        say.error("--truth records when the lidar passes its rear: it needs --lidar")
        return 2
    try:
        truth = args.truth.open("w", buffering=1) if args.truth else None  # a line each: a killed run keeps them
    except OSError as exc:
        say.error(f"--truth {args.truth}: {exc.strerror}")
        return 1
    try:
        endpoint, stopping, log = _open_endpoint(args)
    except EndpointError as exc:
        say.error(f"{exc}")
        if truth is not None:
            truth.close()
        return 1
    extras, closers = _serve_sensors(emu, args.camera_port)
    if log is not None:
        print(
            f"[emulator] {args.robot or args.profile}, seed {args.seed}, {args.baud} baud on {endpoint.name}; "
            "Ctrl-C to stop",
            file=log,
            flush=True,
        )
    try:
        serve(
            emu,
            endpoint,
            stopping,
            dtr_reset_on_open=not args.no_dtr_reset,
            speed=args.speed,
            log=log,
            extras=extras,
            truth=truth,
        )
    finally:
        endpoint.close()
        for close in closers:
            close()
        if truth is not None:
            truth.close()
    return 0


def _serve_sensors(
    emu: Emulator, camera_port: int
) -> tuple[list[tuple[Endpoint, SerialPeripheral]], list[Callable[[], None]]]:
    """A pty per serial sensor and the camera's HTTP server; prints one stdout line for each."""
    rig = emu.sensors
    extras: list[tuple[Endpoint, SerialPeripheral]] = []
    closers: list[Callable[[], None]] = []
    if rig is None:
        return extras, closers
    for kind, dev in rig.devices.items():
        if isinstance(dev, CameraDevice):
            server = MjpegServer(dev, camera_port)
            closers.append(server.close)
            print(f"{kind} {dev.spec.name} {server.url}", flush=True)
        else:
            pty = PtyEndpoint()
            extras.append((pty, dev))
            closers.append(pty.close)
            print(f"{kind} {dev.spec.name} {pty.name}", flush=True)
    return extras, closers


def _board_options(args: argparse.Namespace) -> dict[str, Any]:
    """The line, fault and board options, as both backends take them (docs/emulator.md says which
    the simavr backend refuses)."""
    return {
        "faults": args.faults,
        "baud": args.baud,
        "latency_us": round(args.latency_ms * 1000),
        "drift_ppm": args.drift_ppm,
        "eeprom": args.eeprom,
        "bootloader_ms": args.bootloader_ms,
    }


class EndpointError(Exception):
    """The pty or socket to serve on could not be opened."""


def _open_endpoint(args: argparse.Namespace) -> tuple[Endpoint, Callable[[], bool], TextIO | None]:
    """The pty (or socket) to serve, a stop flag raised by SIGINT/SIGTERM, and the log stream.

    The device path goes to stdout as the first line, which is what callers wait for."""
    try:
        endpoint: Endpoint = SocketEndpoint(args.socket) if args.socket is not None else PtyEndpoint()
    except OSError as exc:
        where = f"TCP port {args.socket} of 127.0.0.1" if args.socket is not None else "a pseudo-terminal"
        raise EndpointError(f"cannot serve on {where}: {exc.strerror or exc}") from exc
    stop_requested = [False]

    def stop(_signum: int, _frame: object) -> None:
        stop_requested[0] = True

    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    print(endpoint.name, flush=True)
    return endpoint, lambda: stop_requested[0], None if args.quiet else sys.stderr


def _simavr_firmware(args: argparse.Namespace) -> tuple[EmulatorProfile, Path]:
    """The profile to emulate and its firmware's ELF: the reference robot's example, or the firmware
    built from the robot file (checked first) with the plant the same file describes."""
    from emulator.backends.simavr.robotfile import file_profile  # noqa: PLC0415 (optional backend)

    if not getattr(args, "robot", None):
        example = get_profile(args.profile).robot.example
        return get_profile(args.profile), firmware.build_example(
            example, out_dir=firmware.BUILD_ROOT / "simavr" / example
        ).elf
    robot = firmware.load_robot(args.robot)
    if robot.board == "pico":
        raise firmware.FirmwareError(
            f"{args.robot} is for the pico: its firmware runs with --backend rp2040, not simavr"
        )
    sketch = firmware.build_sketch_dir(robot)
    built = firmware.build_sketch(sketch, firmware.robot_board(robot, None), sketch.parent / "simavr")
    return file_profile(robot, sketch.name), built.elf


def _rp2040_firmware(args: argparse.Namespace) -> tuple[EmulatorProfile, Path]:
    """The Pico robot (a board = "pico" file, or --profile moved to the Pico pinout) and the flash
    image of its firmware, built for --baud."""
    from emulator.backends.rp2040 import pico_profile, pico_robot  # noqa: PLC0415 (optional backend)
    from roverlink.firmware.pico import build_pico  # noqa: PLC0415

    if args.eeprom != "blank" or args.bootloader_ms is not None:
        raise firmware.FirmwareError(
            "--eeprom and --bootloader-ms: not with --backend rp2040 (the Pico keeps no "
            "configuration and has no serial bootloader)"
        )
    if getattr(args, "robot", None):
        robot = firmware.load_robot(args.robot)
        if robot.board != "pico":
            raise firmware.FirmwareError(
                f'{args.robot} is for the {robot.board}: --backend rp2040 runs a board = "pico" robot file '
                "(docs/firmware.md, Raspberry Pi Pico)"
            )
        name, profile = Path(args.robot).stem, pico_profile(robot)
    else:
        robot, name, profile = pico_robot(args.profile), args.profile, pico_profile(args.profile)
    built = build_pico(robot, firmware.BUILD_ROOT / "pico" / f"{name}-{args.baud}", name=name, baud=args.baud)
    return profile, built.bin


def _cmd_emulate_firmware(args: argparse.Namespace) -> int:
    """A compiled firmware served on a pty: the AVR one in simavr, or the Pico one in rp2040js."""
    from emulator.backends.rp2040 import Rp2040Robot  # noqa: PLC0415 (optional backends)
    from emulator.backends.simavr import SimavrRobot  # noqa: PLC0415

    rp2040 = args.backend == "rp2040"
    robot: SimavrRobot | Rp2040Robot
    try:
        if rp2040:
            profile, image = _rp2040_firmware(args)
            options = {k: v for k, v in _board_options(args).items() if k not in ("eeprom", "bootloader_ms")}
            robot = Rp2040Robot(profile, image, seed=args.seed, **options)
            about = f"{image.name} on the RP2040 (rp2040js) at 125 MHz"
        else:
            profile, elf = _simavr_firmware(args)
            robot = SimavrRobot(profile, elf=elf, seed=args.seed, **_board_options(args))
            about = f"{robot.elf.name} on {robot.harness.wiring.mcu} at 16 MHz"
    except (BackendError, EmulatorError, firmware.FirmwareError) as exc:
        say.error(f"{exc}")
        return 2
    except RobotFileError as exc:
        say.error(exc)
        return 2
    try:
        endpoint, stopping, log = _open_endpoint(args)
    except EndpointError as exc:
        robot.close()
        say.error(f"{exc}")
        return 1
    tag = args.backend
    if log is not None:
        print(
            f"[{tag}] {robot.profile.name}: {about}, seed {args.seed}, {args.baud} baud on {endpoint.name}; "
            "Ctrl-C to stop",
            file=log,
            flush=True,
        )
    # A USB-UART adapter's DTR resets an Arduino through its bootloader's circuit, not a Pico.
    dtr_reset = not args.no_dtr_reset and not rp2040
    try:
        ratio = serve(robot, endpoint, stopping, dtr_reset_on_open=dtr_reset, speed=args.speed, log=log, tag=tag)
    finally:
        endpoint.close()
        robot.close()
    if log is not None:
        print(f"[{tag}] ran {ratio:.1f}x faster than real time while busy", file=log, flush=True)
    return 0
