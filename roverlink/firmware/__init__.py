"""Build and flash the RoverLink Arduino firmware with avr-gcc, as the Arduino IDE would.

    from roverlink import firmware
    result = firmware.build_example("AckermannPiCar")      # cached; prints nothing
    print(result.summary(), result.elf)

boards.py names the boards and examples, toolchain.py finds avr-gcc and the Arduino core and holds
the compiler flags, build.py compiles and links (with an object cache), flash.py writes through
the bootloader, robot.py turns a robot file into a sketch (the fitting example with the file's
robot_profile.h). `roverlink firmware build|flash|sketch` (roverlink/commands/firmware.py) is the command.
"""

from roverlink.firmware.boards import (
    BOARD_BY_PROTO,
    BOARDS,
    BUILD_ROOT,
    LIBRARY_DIR,
    BoardSpec,
    CompileError,
    FirmwareError,
    ToolchainMissingError,
    UnknownNameError,
    board_spec,
    example_board,
    example_dir,
    examples,
)
from roverlink.firmware.build import Builder, BuildResult, build_example, build_sketch
from roverlink.firmware.flash import avrdude_command
from roverlink.firmware.robot import build_sketch_dir, load_robot, robot_board, write_sketch
from roverlink.firmware.toolchain import CORE_DIR_ENV, SIZE_FLAGS, Toolchain, arduino_core_dir

__all__ = [
    "BOARDS",
    "BOARD_BY_PROTO",
    "BUILD_ROOT",
    "CORE_DIR_ENV",
    "LIBRARY_DIR",
    "SIZE_FLAGS",
    "BoardSpec",
    "BuildResult",
    "Builder",
    "CompileError",
    "FirmwareError",
    "Toolchain",
    "ToolchainMissingError",
    "UnknownNameError",
    "arduino_core_dir",
    "avrdude_command",
    "board_spec",
    "build_example",
    "build_sketch",
    "build_sketch_dir",
    "example_board",
    "example_dir",
    "examples",
    "load_robot",
    "robot_board",
    "write_sketch",
]
