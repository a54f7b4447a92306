"""A 9-axis attitude module on a robot driving on flat ground (the JY901's physics and its filter).

Per sample, in the module's body frame (REP-103: x forward, y left, z up):

* accelerometer (g): forward acceleration, centripetal v * wz, and +1 g on z (the specific force
  of standing on the floor), each with white noise of `accel_sigma_g`;
* gyroscope (deg/s): the yaw rate on z, plus a turn-on bias per axis (`gyro_bias_dps` spread) that
  random-walks (`gyro_bias_walk_dps` per sqrt(s)), plus white noise of `gyro_sigma_dps`;
* magnetometer (mG): the Earth's field (`mag_field_mg` horizontal, pointing at magnetic north,
  1.2 times that downwards) seen from the module's heading, plus a hard-iron offset that turns
  into a heading error of a few degrees until the module is calibrated, plus noise;
* the module's own attitude: roll and pitch are the level floor plus `angle_sigma_deg` noise; yaw
  is its filter: the gyro integrated, pulled towards the compass heading with time constant
  `heading_filter_s` (9-axis mode), or the gyro alone (6-axis mode, AXIS6 = 1: it drifts with the
  bias). "Heading zero" (CALSW 4) subtracts the yaw at that moment.

World frame: magnetic north is the world's +y axis unless a scene says otherwise, and the 9-axis
yaw is measured like the robot's heading (counter-clockwise from the world's +x axis), so with a
calibrated magnetometer it converges to the true heading.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from protocol.sensors import ImuSpec

GRAVITY = 9.80665
Motion = Callable[[], tuple[float, float, float]]
"""(world heading rad, forward speed m/s, yaw rate rad/s) of the robot now."""


@dataclass(frozen=True, slots=True)
class ImuSample:
    time_us: int
    accel_g: tuple[float, float, float]
    gyro_dps: tuple[float, float, float]
    mag_mg: tuple[float, float, float]
    angle_deg: tuple[float, float, float]
    """roll, pitch, yaw (the module's filter), yaw in -180..180."""
    quaternion: tuple[float, float, float, float]
    """w, x, y, z of the same attitude."""
    temperature_c: float
    true_heading_rad: float
    """Ground truth: the module's heading in the world (for tests)."""


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


class ImuModel:
    def __init__(self, spec: ImuSpec, rng: np.random.Generator, yaw_offset_rad: float = 0.0) -> None:
        self.spec = spec
        self.rng = rng
        self.yaw_offset_rad = yaw_offset_rad
        """Mounting yaw of the module relative to the robot."""
        self.north_rad = math.pi / 2
        self.gyro_bias = rng.normal(0.0, spec.gyro_bias_dps, 3)
        self.hard_iron = rng.normal(0.0, 0.05 * spec.mag_field_mg, 2)
        self.accel_bias = rng.normal(0.0, 0.005, 3)
        self.axis6 = False
        self.yaw_zero = 0.0
        self._yaw: float | None = None
        self._last: tuple[int, float] | None = None  # (time, speed) of the previous sample

    def calibrate_accel(self) -> None:
        """CALSW 1: level and still; the accelerometer's and the gyro's offsets are measured out."""
        self.accel_bias = self.accel_bias * 0.05
        self.gyro_bias = self.gyro_bias * 0.1

    def calibrate_mag(self) -> None:
        """CALSW 7 then 0: the hard-iron offset is fitted out."""
        self.hard_iron = self.hard_iron * 0.05

    def zero_heading(self) -> None:
        """CALSW 4: the current yaw becomes 0."""
        if self._yaw is not None:
            self.yaw_zero = self._yaw

    def sample(self, time_us: int, motion: Motion) -> ImuSample:
        spec, rng = self.spec, self.rng
        heading, speed, yaw_rate = motion()
        heading += self.yaw_offset_rad
        dt = 0.0 if self._last is None else (time_us - self._last[0]) / 1e6
        accel = (speed - self._last[1]) / dt if self._last is not None and dt > 0 else 0.0
        self._last = (time_us, speed)
        if dt > 0:
            walk = spec.gyro_bias_walk_dps * math.sqrt(dt)
            self.gyro_bias = self.gyro_bias + rng.normal(0.0, walk, 3)
        gyro = self.gyro_bias + rng.normal(0.0, spec.gyro_sigma_dps, 3)
        gyro[2] += math.degrees(yaw_rate)
        acc = np.array([accel / GRAVITY, speed * yaw_rate / GRAVITY, 1.0]) + self.accel_bias
        acc += rng.normal(0.0, spec.accel_sigma_g, 3)
        b = spec.mag_field_mg
        rel = self.north_rad - heading
        mag = np.array([b * math.cos(rel) + self.hard_iron[0], b * math.sin(rel) + self.hard_iron[1], -1.2 * b])
        mag += rng.normal(0.0, spec.mag_sigma_mg, 3)
        compass = _wrap(self.north_rad - math.atan2(mag[1], mag[0]))
        if self._yaw is None:
            self._yaw = 0.0 if self.axis6 else compass
        else:
            self._yaw = _wrap(self._yaw + math.radians(gyro[2]) * dt)
            if not self.axis6 and dt > 0:
                self._yaw = _wrap(self._yaw + dt / spec.heading_filter_s * _wrap(compass - self._yaw))
        yaw = _wrap(self._yaw - self.yaw_zero)
        roll, pitch = rng.normal(0.0, math.radians(spec.angle_sigma_deg), 2)
        return ImuSample(
            time_us=time_us,
            accel_g=(float(acc[0]), float(acc[1]), float(acc[2])),
            gyro_dps=(float(gyro[0]), float(gyro[1]), float(gyro[2])),
            mag_mg=(float(mag[0]), float(mag[1]), float(mag[2])),
            angle_deg=(math.degrees(roll), math.degrees(pitch), math.degrees(yaw)),
            quaternion=quaternion(roll, pitch, yaw),
            temperature_c=25.0 + float(rng.normal(0.0, 0.05)),
            true_heading_rad=heading,
        )


def quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(w, x, y, z) of Z-Y-X Euler angles."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    )
