"""The whole plant of one robot: drive units, ESC, servo, LEDs, body; stepped at a fixed dt."""

from __future__ import annotations

from emulator.plant.encoder import QuadratureEncoder
from emulator.plant.esc import Esc, EscState
from emulator.plant.leds import LedBank
from emulator.plant.motor import DcMotor
from emulator.plant.servo import SteeringServo
from emulator.plant.vehicle import DriveUnit, Vehicle
from emulator.profiles import EmulatorProfile
from protocol.generated.constants import WHEEL_COUNT
from protocol.generated.hardware import MotorMode

WHEEL_CHANNELS = WHEEL_COUNT
"""Wheel channels the firmware addresses (a single-motor robot uses channel 0)."""


class Plant:
    def __init__(self, profile: EmulatorProfile, dt_s: float) -> None:
        self.profile = profile
        self.dt_s = dt_s
        params = profile.plant
        robot = profile.robot
        radius = profile.wheel_radius_m
        reflected = params.motor.reflected_inertia + params.body.wheel_inertia_kg_m2
        units: list[DriveUnit] = []
        for w in range(profile.drive_units):
            motor = DcMotor(params.motor, profile.motor_polarity(w), dt_s)
            encoder = QuadratureEncoder(profile.encoder_cpr, profile.encoder_polarity(w), params.encoder_phase)
            y = 0.0 if profile.ackermann else (profile.track_m / 2 if w == 0 else -profile.track_m / 2)
            units.append(DriveUnit(motor, encoder, y, reflected))
        self.units = units
        self.vehicle = Vehicle(params.body, units, radius, robot.kinematics, robot.wheelbase_m)
        self.esc = Esc(params.esc) if profile.has_esc and params.esc is not None else None
        servo = profile.servo
        self.servo = SteeringServo(servo) if profile.has_servo and servo is not None else None
        self.leds = LedBank()

    # -- what the MCU's pins do (called through the firmware's Board) ---------------------------
    def drive(self, wheel: int, effort_permille: int, mode: MotorMode) -> None:
        if self.esc is None and 0 <= wheel < len(self.units):
            self.units[wheel].motor.command(effort_permille / 1000, mode)

    def esc_pulse(self, pulse_us: int) -> None:
        if self.esc is not None:
            self.esc.set_pulse(pulse_us)

    def steering_pulse(self, pulse_us: int) -> None:
        if self.servo is not None:
            self.servo.set_pulse(pulse_us)

    def lights(self, mask: int) -> None:
        self.leds.set(mask)

    def encoder_counts(self) -> list[int]:
        """Edges counted on each wheel channel since power-up (0 for a channel without an encoder)."""
        counts = [0] * WHEEL_CHANNELS
        for w, unit in enumerate(self.units):
            if unit.encoder is not None:
                counts[w] = unit.encoder.count
        return counts

    def pins_released(self) -> None:
        """MCU in reset: every pin is an input, so bridges are off, no servo or ESC pulses, LEDs dark."""
        for unit in self.units:
            unit.motor.command(0.0, MotorMode.COAST)
        self.esc_pulse(0)
        self.steering_pulse(0)
        self.leds.set(0)

    def power_cycle(self) -> None:
        """The supply dipped: the ESC forgets its calibration as well."""
        if self.esc is not None:
            self.esc.power_cycle()

    # -- physics -------------------------------------------------------------------------------
    def step(self, now_us: int) -> None:
        esc = self.esc
        if esc is not None:
            throttle = esc.step(now_us)
            mode = MotorMode.DRIVE if throttle != 0.0 and esc.state is EscState.READY else MotorMode.COAST
            if mode is MotorMode.COAST and esc.params.drag_brake > 0 and esc.state is EscState.READY:
                mode = MotorMode.BRAKE
            self.units[0].motor.command(throttle, mode)
        steer = 0.0
        if self.servo is not None:
            self.servo.step(self.dt_s)
            steer = self.servo.wheel_angle_rad
        self.vehicle.step(self.dt_s, steer)
