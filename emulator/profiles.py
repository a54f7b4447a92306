"""Emulator profiles: the reference robots' firmware defaults plus plant parameters.

Everything the firmware knows (dimensions, encoder cpr, config and PID defaults, capabilities,
board, feedback mode) comes from `protocol.generated.profiles.PROFILES`, which is generated from
`protocol/spec/robots.toml` like the firmware examples' `robot_profile.h`. This module adds only
what the firmware cannot know: the physics of the motors, ESC, servo and body, and board timing.

The motors are sized so that the default gains fit: at full effort a wheel on the ground turns at
about 1000 / kf mm/s (kf is the feed-forward in permille per mm/s), the loaded mechanical time
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
from emulator.plant.esc import EscParams
from emulator.plant.motor import MotorParams
from emulator.plant.servo import ServoParams
from emulator.plant.vehicle import BodyParams
from protocol.generated.enums import Capability
from protocol.generated.profiles import PROFILES, ROBOT_SENSORS, RobotProfile
from protocol.sensors import RobotSensors


@dataclass(frozen=True, slots=True)
class BoardTiming:
    bootloader_ms: int
    """Time from an external (DTR) reset to the sketch's setup(); power-on skips the bootloader."""
    power_on_ms: int = 70
    """Start-up delay after power-on or brown-out (oscillator start-up and setup())."""
    eeprom_bytes: int = 4096
    eeprom_write_ms: float = 3.4
    """Time to program one changed EEPROM byte; the main loop is stalled meanwhile."""
    rx_buffer_bytes: int = 63
    """Usable bytes of the Arduino core's 64-byte receive ring buffer."""
    micros_resolution_us: int = 4
    """micros() steps of 4 us on a 16 MHz AVR (timer0 prescaler 64)."""


@dataclass(frozen=True, slots=True)
class PlantParams:
    motor: MotorParams
    body: BodyParams
    timing: BoardTiming
    esc: EscParams | None = None
    servo: ServoParams | None = None
    encoder_phase: float = 0.0
    """Fraction of a count between an encoder edge and the power-up position (0: on an edge)."""


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


_MEGA = BoardTiming(bootloader_ms=1500, eeprom_bytes=4096)
_UNO = BoardTiming(bootloader_ms=1000, eeprom_bytes=1024)
TIMINGS: dict[str, BoardTiming] = {"mega2560": _MEGA, "uno": _UNO, "native": _MEGA}
"""Board timing by a robot file's `board` (the native core: the Mega's, the larger EEPROM)."""

PLANTS: dict[str, PlantParams] = {
    # 6 V class metal gearmotor, 30:1, 13-pulse Hall encoder (13 * 4 * 30 = 1560 counts per wheel
    # turn), TB6612 at 6 V; a 1.2 kg car on two 64 mm wheels and a caster.
    "diffdrive-tb6612": PlantParams(
        motor=MotorParams(
            supply_v=6.0,
            resistance_ohm=3.0,
            inductance_h=0.003,
            ke_v_s_rad=0.0085,
            gear_ratio=30.0,
            efficiency=0.7,
            rotor_inertia_kg_m2=5e-7,
            coulomb_nm=0.02,
            viscous_nm_s_rad=1e-4,
            deadband=0.02,
            current_limit_a=3.2,
        ),
        body=BodyParams(
            mass_kg=1.2,
            yaw_inertia_kg_m2=0.008,
            wheel_inertia_kg_m2=2e-5,
            drive_load_fraction=0.8,
            rolling_resistance=0.02,
        ),
        timing=_MEGA,
    ),
    # 12 V JGB37-520 class gearmotor, 19.2:1, 64-count encoder (1216 counts per wheel turn) behind
    # a BTS7960; a 2.5 kg 3D-printed SLAM robot with a lidar on 90 mm wheels.
    "diffdrive-bts7960": PlantParams(
        motor=MotorParams(
            supply_v=12.0,
            resistance_ohm=2.0,
            inductance_h=0.002,
            ke_v_s_rad=0.01875,
            gear_ratio=19.2,
            efficiency=0.75,
            rotor_inertia_kg_m2=1.5e-6,
            coulomb_nm=0.06,
            viscous_nm_s_rad=2e-4,
            deadband=0.03,
            current_limit_a=43.0,
        ),
        body=BodyParams(
            mass_kg=2.5,
            yaw_inertia_kg_m2=0.033,
            wheel_inertia_kg_m2=1e-4,
            drive_load_fraction=0.8,
            rolling_resistance=0.02,
        ),
        timing=_MEGA,
    ),
    # 1/16 PiCar: 3000 kV sensorless inrunner on 2S LiPo (7.4 V) behind an RC ESC, 28:1 from motor
    # to rear axle, encoder on the motor (720 counts per wheel turn); steering servo 65..125 deg.
    "picar": PlantParams(
        motor=MotorParams(
            supply_v=7.4,
            resistance_ohm=0.08,
            inductance_h=1e-5,
            ke_v_s_rad=60 / (2 * math.pi * 3000),
            gear_ratio=28.0,
            efficiency=0.8,
            rotor_inertia_kg_m2=2e-6,
            coulomb_nm=0.08,
            viscous_nm_s_rad=5e-4,
            deadband=0.02,
            current_limit_a=30.0,
        ),
        body=BodyParams(
            mass_kg=1.6,
            yaw_inertia_kg_m2=0.022,
            wheel_inertia_kg_m2=1e-4,
            drive_load_fraction=0.55,
            rolling_resistance=0.02,
        ),
        timing=_UNO,
        esc=EscParams(),
        servo=ServoParams(travel_min_deg=60.0, travel_max_deg=130.0, resolution_deg=0.5, slew_deg_s=400.0),
    ),
}

PROFILE_NAMES: tuple[str, ...] = tuple(PROFILES)


def get_profile(name: str) -> EmulatorProfile:
    """The emulator profile of a reference robot; UnknownProfileError lists the valid names."""
    robot = PROFILES.get(name)
    plant = PLANTS.get(name)
    if robot is None or plant is None:
        raise UnknownProfileError(name, sorted(set(PROFILES) & set(PLANTS)))
    return EmulatorProfile(robot=robot, plant=plant)
