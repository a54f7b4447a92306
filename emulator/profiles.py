"""Emulator profiles: the reference robots' firmware defaults plus plant parameters.

Everything the firmware knows (dimensions, encoder cpr, config and PID defaults, capabilities,
board, feedback mode) comes from `protocol.generated.profiles.PROFILES`, which is generated from
the reference robots' files (protocol/robots/*.toml) like the firmware examples' `robot_profile.h`.
What the firmware cannot know, the physics of the motors, ESC, servo and body, is in the same files'
[emulator.*] sections; emulator.plant.params builds the models from them, with the board's timing.

The reference motors are sized so that the default gains fit: at full effort a wheel on the ground
turns at about 1000 / kf mm/s (kf is the feed-forward in permille per mm/s), the loaded mechanical time
constant is 40..80 ms, and friction plus the driver deadband need 7..9 % effort to get moving.
The wiring matches the example's defaults: a wheel whose `motor_invert` / `encoder_invert` bit is
set has its motor / encoder mounted mirrored, so the default config drives it the right way.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from emulator.errors import UnknownProfileError
from emulator.physical import NOMINAL, Physical
from emulator.plant.params import TIMINGS, BoardTiming, PlantParams, plant_from_file
from emulator.plant.servo import ServoParams
from protocol.generated.enums import Capability
from protocol.generated.profiles import PROFILES, ROBOT_SENSORS, RobotProfile
from protocol.robotfile import REFERENCES, load, reference_path
from protocol.sensors import RobotSensors

__all__ = [
    "PLANTS",
    "PROFILE_NAMES",
    "TIMINGS",
    "BoardTiming",
    "EmulatorProfile",
    "PlantParams",
    "get_profile",
]


@dataclass(frozen=True, slots=True)
class EmulatorProfile:
    robot: RobotProfile
    """Firmware defaults, dimensions and capabilities from PROFILES."""
    plant: PlantParams
    physical: Physical = NOMINAL
    """How the robot is really built where it differs from its configuration (emulator.physical)."""
    body: RobotSensors | None = None
    """Footprint and sensor mounts; None: the reference robot's (protocol/spec/sensors.toml)."""
    robot_file: str | None = None
    """The robot file this profile was built from (emulator.robot_file), None for a reference robot."""

    @property
    def name(self) -> str:
        return self.robot.name

    @property
    def sensors(self) -> RobotSensors:
        """Where the robot carries its sensors and how big it is (the world's collisions, the rig)."""
        return self.body if self.body is not None else ROBOT_SENSORS[self.robot.name]

    @property
    def ackermann(self) -> bool:
        return self.robot.kinematics == "ackermann"

    @property
    def wheel_radius_m(self) -> float:
        """The plant's true wheel radius."""
        return self.robot.wheel_diameter_m / 2 * self.physical.wheel_scale

    @property
    def track_m(self) -> float:
        """The plant's true track width (0 for Ackermann: one drive unit on the axle's midpoint)."""
        return self.robot.track_m * self.physical.track_scale

    @property
    def encoder_cpr(self) -> int:
        """The plant's true encoder counts per wheel revolution."""
        return round(self.robot.encoder_cpr * self.physical.cpr_scale)

    @property
    def servo(self) -> ServoParams | None:
        """The steering servo and linkage as built (the true straight-ahead angle and ratio)."""
        servo = self.plant.servo
        if servo is None:
            return None
        phys = self.physical
        return dataclasses.replace(
            servo,
            straight_deg=servo.straight_deg + phys.steering_trim_deg,
            linkage_ratio=servo.linkage_ratio * phys.steering_ratio,
        )

    def with_physical(self, physical: Physical) -> EmulatorProfile:
        return dataclasses.replace(self, physical=physical)

    @property
    def drive_units(self) -> int:
        """Motors with a wheel (and an encoder): 2 for differential drive, 1 (rear axle) for Ackermann."""
        return 1 if self.ackermann else 2

    def motor_polarity(self, wheel: int) -> int:
        mirrored = (self.robot.config.motor_invert ^ self.physical.motor_flip) >> wheel & 1
        return -1 if mirrored else 1

    def encoder_polarity(self, wheel: int) -> int:
        mirrored = (self.robot.config.encoder_invert ^ self.physical.encoder_flip) >> wheel & 1
        return -1 if mirrored else 1

    @property
    def has_esc(self) -> bool:
        return bool(self.robot.capabilities & Capability.ESC)

    @property
    def has_servo(self) -> bool:
        return bool(self.robot.capabilities & Capability.STEERING_SERVO)

    def time_constant_s(self) -> float:
        """Loaded mechanical time constant of a straight-line speed change, from the parameters:
        (J_wheel + J_rotor G^2 + m_share r^2) / (emf damping + viscous)."""
        m, r = self.plant.motor, self.wheel_radius_m
        body = self.plant.body
        units = self.drive_units
        inertia = body.wheel_inertia_kg_m2 + m.reflected_inertia + body.mass_kg * r * r / units
        return inertia / (m.emf_damping + m.viscous_nm_s_rad)

    def free_speed_mm_s(self, duty: float = 1.0) -> float:
        """Steady straight-line rim speed at a motor duty (after the deadband), on flat ground."""
        m, r, body = self.plant.motor, self.wheel_radius_m, self.plant.body
        units = self.drive_units
        if abs(duty) <= m.deadband:
            return 0.0
        d_eff = (abs(duty) - m.deadband) / (1 - m.deadband)
        load = body.mass_kg * 9.81 * body.drive_load_fraction / units
        dry = m.coulomb_nm + body.rolling_resistance * load * r
        drive = m.torque_per_volt * m.supply_v * d_eff
        if drive <= dry:
            return 0.0
        return math.copysign((drive - dry) / (m.emf_damping + m.viscous_nm_s_rad) * r * 1000, duty)


def _plant(name: str) -> PlantParams:
    robot = load(reference_path(name))
    return plant_from_file(robot, stand_in=robot)


PLANTS: dict[str, PlantParams] = {name: _plant(name) for name in REFERENCES}
"""Each reference robot's plant, from its robot file's [emulator.*] sections (protocol/robots/)."""

PROFILE_NAMES: tuple[str, ...] = tuple(PROFILES)


def get_profile(name: str) -> EmulatorProfile:
    """The emulator profile of a reference robot; UnknownProfileError lists the valid names."""
    robot = PROFILES.get(name)
    plant = PLANTS.get(name)
    if robot is None or plant is None:
        raise UnknownProfileError(name, sorted(set(PROFILES) & set(PLANTS)))
    return EmulatorProfile(robot=robot, plant=plant)
