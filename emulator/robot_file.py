"""An emulator profile built from a robot file (`emu://?robot=PATH`, `roverlink emulate --robot`).

What the file says goes to both halves, as it would on a real robot built and flashed from it:

- the firmware model's defaults: SET_CONFIG (calibrated values included), SET_PID, capabilities,
  feedback mode and the robot's name (what IDENTITY reports); the board's timing and EEPROM size;
- the plant: wheel diameter, track, wheelbase, encoder counts per turn and directions, motor
  directions, the ESC's pulse range, the steering servo's pulse range and straight-ahead angle, and
  the footprint and sensor mounts.

The plant is built as the file's nominal geometry says ([geometry], encoders.counts_per_rev):
[calibration] holds measurements the firmware is configured with, not a different robot; the URL's
`physical=` / scale parameters make the real robot differ. The physics (motor constants and
gearbox, friction, inertia, the servo's speed, the ESC's arming) are the file's [emulator.*]
sections; a section the file leaves out is the nearest reference robot's (`nearest_reference`).
"""

from __future__ import annotations

from pathlib import Path

from emulator.plant.params import PlantParams, plant_from_file
from emulator.profiles import PLANTS, EmulatorProfile
from protocol.generated.profiles import PROFILES, RobotProfile
from protocol.robotfile import RobotFile, load, reference_path


def _driver(profile: RobotProfile) -> str:
    return "ESC+servo" if profile.wiring.esc_pin is not None else profile.wiring.motors[0].kind


def nearest_reference(robot: RobotFile) -> str:
    """The reference robot whose motors, friction and inertia the file's robot gets: of the same
    drive kind, the one with the same driver, else (ties too) the closest wheel diameter."""
    kind = "diff" if robot.drive.kind == "differential" else "ackermann"
    same_kind = [p for p in PROFILES.values() if p.kinematics == kind and p.name in PLANTS]

    def distance(p: RobotProfile) -> tuple[bool, float, str]:
        return _driver(p) != robot.drive.driver, abs(p.wheel_diameter_m - robot.geometry.wheel_diameter_m), p.name

    return min(same_kind, key=distance).name


def firmware_defaults(robot: RobotFile) -> RobotProfile:
    """The file as the firmware model takes a reference profile; the dimensions are the nominal
    ones the plant is built with (the config carries the calibrated ones)."""
    return RobotProfile(
        name=robot.name,
        example=robot.name,  # IDENTITY.robot_name: the file's firmware reports the robot's name
        doc=robot.description,
        board=robot.board_enum(),
        capabilities=robot.capabilities(),
        kinematics="diff" if robot.drive.kind == "differential" else "ackermann",
        feedback_mode=robot.feedback_mode(),
        lights_mode=robot.lights_mode(),
        track_m=robot.geometry.track_m,
        wheelbase_m=robot.geometry.wheelbase_m,
        wheel_diameter_m=robot.geometry.wheel_diameter_m,
        encoder_cpr=robot.encoders.counts_per_rev,
        config=robot.config(),
        pid=robot.pid_gains(),
        wiring=robot.wiring,
    )


def plant_for(robot: RobotFile, reference: str) -> PlantParams:
    """The file's plant: its [emulator.*] sections, gearbox, pulses and board; each section it
    leaves out, the `reference` robot's."""
    return plant_from_file(robot, load(reference_path(reference)))


def profile_from_file(path: str | Path) -> EmulatorProfile:
    """The emulated robot the file at `path` describes; RobotFileError (a ValueError) names the
    file, line, key and value of every problem in it."""
    robot = load(path)
    return EmulatorProfile(
        robot=firmware_defaults(robot),
        plant=plant_for(robot, nearest_reference(robot)),
        body=robot.sensors(),
        robot_file=str(path),
    )
