"""A user's robot file (protocol.robotfile) as the profile the simavr backend runs: the firmware
defaults, dimensions and pins from the file (the firmware built from it has the same), the plant's
physics from its [emulator.*] sections (each one it leaves out: the reference robot's with the same
driver), and the board's timing.

    profile = file_profile(protocol.robotfile.load("my.toml"), "AckermannPiCar")
    SimavrRobot(profile, elf=...)

The file is the truth here: the plant is built as the file says (nominal, no physical errors).
"""

from __future__ import annotations

from emulator.errors import EmulatorValueError
from emulator.plant.params import plant_from_file
from emulator.profiles import EmulatorProfile as Profile
from emulator.profiles import get_profile
from protocol.generated.profiles import RobotProfile
from protocol.robotfile import RobotFile, load, reference_path

PLANT_OF_DRIVER = {"TB6612": "diffdrive-tb6612", "L298N": "diffdrive-tb6612", "BTS7960": "diffdrive-bts7960"}
PLANT_OF_DRIVER["ESC+servo"] = "picar"
"""The reference robot whose motors (and ESC, servo) stand in for a file's driver."""
BOARDS = ("uno", "mega2560")
"""The boards simavr runs."""


def file_profile(robot: RobotFile, example: str) -> Profile:
    """The profile of the robot in `robot` running `example`'s firmware built from it."""
    if robot.board not in BOARDS:
        raise EmulatorValueError("board", robot.board, f"a board simavr runs: {', '.join(BOARDS)}")
    plant = plant_from_file(robot, load(reference_path(PLANT_OF_DRIVER[robot.drive.driver])))
    reference = get_profile(PLANT_OF_DRIVER[robot.drive.driver]).robot
    config = robot.config()
    return Profile(
        robot=RobotProfile(
            name=robot.name,
            example=example,
            doc=robot.description,
            board=robot.board_enum(),
            capabilities=robot.capabilities(),
            kinematics=reference.kinematics,
            feedback_mode=robot.feedback_mode(),
            lights_mode=robot.lights_mode(),
            track_m=robot.track_m,
            wheelbase_m=robot.geometry.wheelbase_m,
            wheel_diameter_m=config.wheel_diameter_um / 1e6,
            encoder_cpr=config.encoder_cpr,
            config=config,
            pid=robot.pid_gains(),
            wiring=robot.wiring,
        ),
        plant=plant,
    )
