"""`roverlink firmware build | flash | sketch`: the Arduino firmware without the Arduino IDE
(roverlink.firmware), for an example, a sketch of your own or a robot file (`--robot FILE`)."""

from __future__ import annotations

import argparse
import shlex
import shutil
import subprocess
from collections.abc import Callable
from pathlib import Path

from serial.tools import list_ports

from protocol.robotfile import RobotFileError
from roverlink import say
from roverlink.firmware import (
    BOARDS,
    BoardSpec,
    Builder,
    CompileError,
    FirmwareError,
    ToolchainMissingError,
    UnknownNameError,
    avrdude_command,
    board_spec,
    build_sketch_dir,
    example_board,
    example_dir,
    examples,
    load_robot,
    robot_board,
    write_sketch,
)
from roverlink.firmware.pico import PicoBuild, bootsel_drives, build_pico, flash_uf2


def _known_ports() -> list[str]:
    return sorted(str(p.device) for p in list_ports.comports())


def _targets(args: argparse.Namespace) -> list[tuple[Path, BoardSpec]]:
    if getattr(args, "robot", None):
        # Checked before anything is written: a file with a problem builds and flashes nothing.
        robot = load_robot(args.robot)
        board_of_file = robot_board(robot, args.board)
        return [(build_sketch_dir(robot), board_of_file)]
    board = board_spec(args.board) if args.board else None
    if args.sketch:
        if board is None:
            raise FirmwareError(f"--sketch needs --board (one of {', '.join(BOARDS)})")
        return [(Path(args.sketch), board)]
    if args.example:
        return [(example_dir(args.example), board or example_board(args.example))]
    # No example named: every example for its own board (or only those targeting --board).
    targets = [(path, example_board(name)) for name, path in examples().items()]
    if board is not None:
        targets = [(path, spec) for path, spec in targets if spec == board]
    return targets


def _out(args: argparse.Namespace, sketch: Path, board: BoardSpec) -> Path:
    """Where the ELF and HEX go: --out, else where the user is: ./firmware/<name>/<board>/ in the
    current directory, <name> the robot file's (its stem) or the sketch's."""
    if args.out:
        return Path(args.out)
    name = Path(args.robot).stem if getattr(args, "robot", None) else sketch.name
    return Path.cwd() / "firmware" / name / board.name


def _pico(args: argparse.Namespace) -> PicoBuild | None:
    """A robot file for the Pico built (ELF, flash image, UF2) into --out or ./firmware/<name>/pico;
    None for any other target."""
    if not getattr(args, "robot", None):
        return None
    robot = load_robot(args.robot)
    if robot.board != "pico":
        return None
    if args.board is not None:
        raise FirmwareError(f"{robot.path} is for the pico, not the {args.board}: leave --board out")
    name = Path(args.robot).stem
    return build_pico(robot, Path(args.out) if args.out else Path.cwd() / "firmware" / name / "pico", name=name)


def cmd_build(args: argparse.Namespace) -> int:
    """Compile examples (or a sketch) into ELF and HEX and print their flash and SRAM use."""
    pico = _pico(args)
    if pico is not None:
        print(pico.summary())
        print(f"  {pico.uf2}")
        return 0
    targets = _targets(args)
    if args.out and len(targets) > 1:
        raise FirmwareError("--out needs a single --example or --sketch")
    for sketch, board in targets:
        result = Builder(board, lto=not args.no_lto).build(sketch, _out(args, sketch, board))
        print(result.summary())
        print(f"  {result.hex}")
    return 0


def cmd_flash(args: argparse.Namespace) -> int:
    """Build an example (or sketch) and write it to a board through its bootloader with avrdude;
    a Pico's firmware is copied to its BOOTSEL drive."""
    pico = _pico(args)
    if pico is not None:
        print(pico.summary())
        if args.port:
            raise FirmwareError(
                f"--port {args.port}: a Pico is flashed through its BOOTSEL drive (--drive DIR), not a port"
            )
        if args.dry_run:
            drives = [Path(args.drive)] if args.drive else bootsel_drives()
            print(f"# copy {pico.uf2} to {drives[0] if drives else 'the RPI-RP2 drive (none is mounted)'}")
            return 0
        print(f"copied to {flash_uf2(pico.uf2, Path(args.drive) if args.drive else None)}")
        return 0
    if args.port is None:
        raise FirmwareError("--port is needed: the serial port of the board, e.g. /dev/ttyACM0")
    ((sketch, board),) = _targets(args)
    hex_file = _out(args, sketch, board).resolve() / f"{sketch.name}.hex"
    if args.dry_run:
        which = f"--sketch {sketch}" if args.sketch else f"--example {sketch.name}"
        which = f"--robot {args.robot}" if args.robot else f"{which} --board {board.name}"
        print(f"# build first: roverlink firmware build {which}")
        print(shlex.join(avrdude_command(board, hex_file, args.port)))
        return 0
    avrdude = shutil.which("avrdude")
    if avrdude is None:
        raise ToolchainMissingError(
            "avrdude not found on PATH: install the Debian package avrdude (sudo apt-get install avrdude)"
        )
    if not Path(args.port).exists() and "://" not in args.port:
        ports = _known_ports()
        raise UnknownNameError("port", args.port, ports)
    result = Builder(board, lto=not args.no_lto).build(sketch, _out(args, sketch, board))
    print(result.summary())
    cmd = avrdude_command(board, result.hex, args.port, avrdude)
    print(shlex.join(cmd), flush=True)
    return subprocess.run(cmd, check=False).returncode


def cmd_sketch(args: argparse.Namespace) -> int:
    """Write an Arduino IDE sketch folder for a robot file: the example that fits it, and the
    robot_profile.h generated from the file."""
    robot = load_robot(args.robot)
    folder = write_sketch(robot, Path(args.folder), force=args.force)
    print(f"{folder}: {folder.name}.ino and robot_profile.h for {robot.name} ({robot.board})")
    print(f"  build it: roverlink firmware build --sketch {folder} --board {robot.board}")
    return 0


def _add_target_options(p: argparse.ArgumentParser, *, example_required: bool) -> None:
    which = p.add_mutually_exclusive_group(required=example_required)
    try:
        names = ", ".join(examples())
    except FirmwareError:  # an installed package without the Arduino library
        names = "a folder of the library's examples/"
    which.add_argument(
        "--example",
        metavar="NAME",
        help=f"example sketch of the library to flash: {names}"
        if example_required
        else f"example sketch of the library: {names} (default: every example)",
    )
    which.add_argument("--sketch", metavar="DIR", help="a sketch folder of your own (needs --board)")
    which.add_argument(
        "--robot",
        metavar="FILE",
        help="a robot file (docs/robot-file.md): the example that fits it with its robot_profile.h, for its board",
    )
    p.add_argument(
        "--board",
        choices=sorted(BOARDS),
        help="target AVR board (default: the one the example's robot profile names; a Pico robot file needs none)",
    )
    p.add_argument(
        "--out",
        metavar="DIR",
        help="where the ELF and HEX (a Pico: ELF, BIN and UF2) go (default: ./firmware/<sketch>/<board> in the "
        "current directory; --robot: ./firmware/<file name>/<board>)",
    )
    p.add_argument("--no-lto", action="store_true", help="link without link-time optimisation (the AVR builds)")


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Registers `roverlink firmware build|flash` on the main CLI's subcommands."""
    fw = sub.add_parser(
        "firmware",
        help="build and flash the firmware (avr-gcc and avrdude; a Pico: arm-none-eabi-gcc, its BOOTSEL drive)",
        description="Build the library's example sketches (or your own) with avr-gcc and flash them with avrdude; "
        "a robot file for a Pico builds with arm-none-eabi-gcc and flashes by copying its UF2 to the BOOTSEL drive.",
    )
    fw_sub = fw.add_subparsers(dest="firmware_command", required=True, metavar="{build,flash,sketch}")
    build = fw_sub.add_parser("build", help=cmd_build.__doc__, description=cmd_build.__doc__)
    _add_target_options(build, example_required=False)
    build.set_defaults(func=_guarded(cmd_build))
    flash = fw_sub.add_parser("flash", help=cmd_flash.__doc__, description=cmd_flash.__doc__)
    _add_target_options(flash, example_required=True)
    flash.add_argument("--port", help="serial port of the board, e.g. /dev/ttyACM0 (not for a Pico)")
    flash.add_argument("--drive", metavar="DIR", help="a Pico's BOOTSEL drive (default: the one mounted)")
    flash.add_argument(
        "--dry-run", action="store_true", help="print the avrdude command (a Pico: the copy) instead of running it"
    )
    flash.set_defaults(func=_guarded(cmd_flash))
    sketch = fw_sub.add_parser("sketch", help=cmd_sketch.__doc__, description=cmd_sketch.__doc__)
    sketch.add_argument("--robot", metavar="FILE", required=True, help="the robot file (docs/robot-file.md)")
    sketch.add_argument("folder", metavar="DIR", help="the sketch folder to write (its name names the .ino)")
    sketch.add_argument("--force", action="store_true", help="overwrite the folder's .ino and robot_profile.h")
    sketch.set_defaults(func=_guarded(cmd_sketch))


def _guarded(command: Callable[[argparse.Namespace], int]) -> Callable[[argparse.Namespace], int]:
    """Turns a FirmwareError into one `error:` line and exit status 2 (1 for a failed compile)."""

    def run(args: argparse.Namespace) -> int:
        try:
            return command(args)
        except CompileError as exc:
            say.error(f"{exc}")
            return 1
        except FirmwareError as exc:
            say.error(f"{exc}")
            return 2
        except RobotFileError as exc:
            say.error(exc)
            return 2

    run.__doc__ = command.__doc__
    return run
