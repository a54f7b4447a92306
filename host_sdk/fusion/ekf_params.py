"""The fusion filter's tunables (`EkfParams`) and the defaults per kind of robot (`params_for`)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from host_sdk.kinematics import Ackermann, DiffDrive

CHI2_1DOF_99 = 6.635
CHI2_1DOF_999 = 10.83


@dataclass(frozen=True, slots=True)
class EkfParams:
    gyro_arw: float = math.radians(0.005)
    """Gyro angle random walk, rad/sqrt(s) (white rate noise density)."""
    bias_walk: float = math.radians(0.01)
    """Gyro bias random walk, rad/s per sqrt(s)."""
    bias_sigma0: float = math.radians(0.3)
    """Initial bias uncertainty, rad/s."""
    distance_noise: float = 0.02
    """Wheel distance error, as a fraction of the distance."""
    slip_distance_noise: float = 0.3
    """... while the wheels slip: a common error of the slipping steps (the tyres spin or slide for
    a while, not a step at a time)."""
    slip_time_s: float = 1.0
    """How long the wheels' distance error stays after slip was last seen."""
    wheel_turn_noise: float = 0.002
    """Random walk of the wheels' heading error per turn, beyond the scale error the filter learns,
    rad per sqrt(rad) (tyres scrubbing through a turn)."""
    turn_scale_sigma0: float = 0.1
    """Initial uncertainty of the wheels' turn scale (track width or steering calibration), fraction."""
    turn_scale_walk: float = 1e-4
    """How fast that scale may change (tyre wear, load), fraction per sqrt(s)."""
    wheel_turn_per_m: float = 0.003
    """Random walk of the wheels' heading error per distance (uneven wheels, floor), rad per sqrt(m)."""
    turn_transient_s: float = 0.05
    """Wheel heading error per change of the turn rate between steps, s (slip while the tyres take
    up a new rate; a steering servo still slewing to its new angle)."""
    distance_transient_s: float = 0.1
    """Wheel distance error per change of the wheels' speed between steps, s (tyres slip while they
    take up a new speed; on a straight a gyro cannot see it)."""
    wheel_heading_resolution: float = 1e-3
    """The wheels' heading quantum (one encoder count: metres per count over the track), rad."""
    sync_s: float = 0.005
    """Timing mismatch between the wheels' and the gyro's clocks (heading error = rate * sync)."""
    heading_sigma: float = math.radians(5.0)
    """Magnetometer heading error that depends on the heading, before the filter has learnt it: the
    prior of each coefficient of its harmonics (a hard-iron offset gives a cos and sin of the heading,
    soft iron of twice the heading), rad."""
    heading_residual_sigma: float = math.radians(1.0)
    """... what the harmonics leave (motor currents, tilt, nearby steel), rad: it changes as the robot turns."""
    heading_noise: float = math.radians(1.0)
    """Magnetometer heading noise from sample to sample, rad."""
    heading_correlation_rad: float = 1.0
    """How far the robot turns before the compass's residual error is another one, rad."""
    gate: float = CHI2_1DOF_99
    """A step whose wheel heading is this far off (chi-square, 1 dof) is slip."""
    drift_gate: float = CHI2_1DOF_999
    """... and so is a running average of the disagreement this far from zero."""


DIFF_DRIVE_PARAMS = EkfParams(wheel_turn_noise=0.0005, wheel_turn_per_m=0.0005, turn_transient_s=0.002)
"""A differential drive's wheels: its heading is the difference of two encoders' counts, with no
steering servo slewing behind its command or moving in coarse steps, so while the tyres grip it is
right to a count and far better per turn and per metre than a car's (which the defaults are for).
Slip beyond that is caught by the gate."""


def params_for(kinematics: DiffDrive | Ackermann | None, params: EkfParams | None = None) -> EkfParams:
    """`params` (by default EkfParams(), or DIFF_DRIVE_PARAMS for a differential drive) with this
    robot's wheel heading quantum where it is coarser than theirs: a differential drive's encoder
    count over its track. (A car's heading comes from its distance counts times the steering's
    curvature, far finer.)"""
    if not isinstance(kinematics, DiffDrive):
        return params or EkfParams()
    p = params or DIFF_DRIVE_PARAMS
    quantum = kinematics.metres_per_count / kinematics.track_m
    if quantum > p.wheel_heading_resolution:
        return dataclasses.replace(p, wheel_heading_resolution=quantum)
    return p
