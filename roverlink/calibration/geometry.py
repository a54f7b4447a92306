"""The arithmetic of calibration: each measurement turned into a configuration value.

Pure functions, so each rule is tested on its own (tests/roverlink/tools/test_tools_calibrate.py).
"""

from __future__ import annotations

import math


def direction_bits(
    motor_invert: int, encoder_invert: int, wheel: int, turned_forward: bool, counts_delta: int
) -> tuple[int, int]:
    """motor_invert / encoder_invert after a positive effort on `wheel` turned it forward or not
    (what the person saw) while its encoder counted `counts_delta` (as the board reported it).
    Wanted: positive effort drives forward, forward motion counts up."""
    bit = 1 << wheel
    if not turned_forward:
        motor_invert ^= bit
    moved = 1 if turned_forward else -1
    if counts_delta * moved < 0:
        encoder_invert ^= bit
    return motor_invert, encoder_invert


def counts_per_rev(counts: int, revolutions: float) -> int:
    """Encoder counts per wheel revolution from counts over a number of turns."""
    if revolutions <= 0:
        raise ValueError(f"revolutions = {revolutions!r}: the wheel must have turned forward")
    return round(abs(counts) / revolutions)


def scaled(value: float, believed: float, measured: float) -> float:
    """A length the board believes made `believed` metres that measured `measured`: the value
    that would have made it right (wheel diameter from a driven distance; track from a turn, the
    other way round: see track_width)."""
    if believed <= 0 or measured <= 0:
        raise ValueError(f"need positive distances: odometry {believed!r}, measured {measured!r}")
    return value * measured / believed


def track_width(track_m: float, odometry_rad: float, measured_rad: float) -> float:
    """Track width from an in-place rotation: odometry's angle is (dR - dL) / track, so a track
    too small makes it too large."""
    if odometry_rad * measured_rad <= 0:
        raise ValueError(f"odometry turned {odometry_rad:.3f} rad but the robot {measured_rad:.3f} rad")
    return track_m * odometry_rad / measured_rad


def arc_through(forward_m: float, left_m: float) -> tuple[float, float]:
    """(arc length, curvature) of the circle that leaves the origin heading along +x and passes
    through (forward, left): what a straight-ish or turning drive did, from where it ended."""
    chord2 = forward_m * forward_m + left_m * left_m
    if chord2 <= 0:
        raise ValueError("the robot did not move")
    kappa = 2 * left_m / chord2
    chord = math.sqrt(chord2)
    if abs(kappa) < 1e-9:
        return chord, 0.0
    half = math.asin(max(-1.0, min(1.0, kappa * chord / 2)))
    if forward_m < 0:  # more than half a circle
        half = math.copysign(math.pi, half) - half
    return abs(2 * half / kappa), kappa


def steering_from_circles(
    kappa_left: float, kappa_right: float, wheelbase_m: float, step_deg: float
) -> tuple[float, float]:
    """(linkage ratio, servo trim in degrees) from drives at one servo step left and right.

    The wheels point at r * (servo - straight): with the servo commanded to centre +- step and
    straight = centre + trim, delta(+-) = r * (+-step - trim)."""
    d_left = math.degrees(math.atan(kappa_left * wheelbase_m))
    d_right = math.degrees(math.atan(kappa_right * wheelbase_m))
    ratio = (d_left - d_right) / (2 * step_deg)
    if ratio <= 0:
        raise ValueError(f"steering one step left turned {d_left:.1f} deg and right {d_right:.1f} deg")
    trim = -(d_left + d_right) / (2 * ratio)
    return ratio, trim


def servo_span_for(servo_min_us: int, servo_max_us: int, center_cdeg: int, ratio: float) -> tuple[int, int]:
    """servo_min_us / servo_max_us such that the board's angles are the wheels' angles: the pulse
    span divided by the linkage ratio, pivoting on the centre's pulse."""
    span = servo_max_us - servo_min_us
    pulse_center = servo_min_us + center_cdeg * span / 18000
    new_span = span / ratio
    new_min = round(pulse_center - center_cdeg * new_span / 18000)
    return new_min, new_min + round(new_span)
