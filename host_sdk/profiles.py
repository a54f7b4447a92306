"""The reference robots by name, and their kinematics.

    >>> from host_sdk.profiles import PROFILES, kinematics_for
    >>> kinematics_for("diffdrive-tb6612")
    DiffDrive(wheel_radius_m=0.032, track_m=0.2, counts_per_rev=1560)

`PROFILES` is generated from the reference robots' files, protocol/robots/*.toml (where the
firmware examples' defaults come from). Geometry the firmware does not know (track width, wheelbase) comes from the
profile; wheel diameter and encoder counts per revolution come from the board's live configuration
when one is given, because those are the numbers the firmware itself uses.
"""

from __future__ import annotations

import math

from host_sdk import checks
from host_sdk.errors import ArgumentTypeError, CommandRangeError
from host_sdk.kinematics import Ackermann, DiffDrive
from protocol.generated.messages import SetConfig
from protocol.generated.profiles import PROFILES, RobotProfile

__all__ = [
    "PROFILES",
    "RobotProfile",
    "get_profile",
    "kinematics_for",
    "kinematics_from",
    "profile_for_example",
    "steering_angles",
    "steering_limits",
]


def get_profile(name: str, *, argument: str = "name") -> RobotProfile:
    """The reference robot called `name`; CommandRangeError lists the names (and calls the bad
    value `argument`: the caller's name for it)."""
    allowed = f"one of {', '.join(PROFILES)}"
    if not isinstance(name, str):
        raise ArgumentTypeError(argument, name, allowed)
    profile = PROFILES.get(name)
    if profile is None:
        raise CommandRangeError(argument, name, allowed)
    return profile


def profile_for_example(example: str) -> RobotProfile | None:
    """The profile whose firmware example is `example` (what IDENTITY.robot_name carries)."""
    checks.instance("example", example, str, "a firmware example name (str)")
    for profile in PROFILES.values():
        if profile.example == example:
            return profile
    return None


def steering_limits(config: SetConfig) -> tuple[float, float]:
    """(right, left) steering limits in radians, as positive numbers, from the servo config."""
    checks.instance("config", config, SetConfig, "a RobotConfig (robot.config)")
    left = math.radians((config.steering_max_cdeg - config.steering_center_cdeg) / 100)
    right = math.radians((config.steering_center_cdeg - config.steering_min_cdeg) / 100)
    return max(0.0, right), max(0.0, left)


def steering_angles(config: SetConfig) -> tuple[float, ...]:
    """The front-wheel angles (rad, left positive, ascending) the servo actually reaches: with a
    `steering_step_cdeg` the firmware clamps the angle asked for to the servo's range, rounds it to
    centre + k * step (half away from centre) and clamps again, so a coarse servo has a few angles
    only, not always the same number each side (the PiCar's: -25, -15, 0, 15 and 30 degrees). Without
    a step, the two limits and the centre."""
    checks.instance("config", config, SetConfig, "a RobotConfig (robot.config)")
    lo, hi, centre = config.steering_min_cdeg, config.steering_max_cdeg, config.steering_center_cdeg
    step = config.steering_step_cdeg
    if step <= 0:
        reach = {lo, centre, hi}
    else:
        ks = range(_round_away((lo - centre) / step), _round_away((hi - centre) / step) + 1)
        reach = {min(hi, max(lo, centre + k * step)) for k in ks}
    return tuple(sorted(math.radians((cdeg - centre) / 100) for cdeg in reach))


def _round_away(x: float) -> int:
    return int(math.copysign(math.floor(abs(x) + 0.5), x))


def kinematics_for(profile: str | RobotProfile, config: SetConfig | None = None) -> DiffDrive | Ackermann:
    """DiffDrive or Ackermann for a reference robot, with the board's `config` if given."""
    prof = profile if isinstance(profile, RobotProfile) else get_profile(profile, argument="profile")
    if config is not None:
        checks.instance("config", config, SetConfig, "a RobotConfig (robot.config), or None for the profile's")
    return kinematics_from(prof.kinematics, prof.track_m, prof.wheelbase_m, config or prof.config)


def kinematics_from(kind: str, track_m: float, wheelbase_m: float, config: SetConfig) -> DiffDrive | Ackermann:
    """DiffDrive ("diff") or Ackermann ("ackermann") from a robot's geometry and firmware `config`
    (wheel diameter, counts per revolution, steering range): reference robots and robot files alike."""
    radius = config.wheel_diameter_um / 2e6
    if kind == "diff":
        return DiffDrive(wheel_radius_m=radius, track_m=track_m, counts_per_rev=config.encoder_cpr)
    right, left = steering_limits(config)
    return Ackermann(
        wheelbase_m=wheelbase_m,
        wheel_radius_m=radius,
        counts_per_rev=config.encoder_cpr,
        max_steering_rad=min(max(left, right), math.radians(89)) or math.radians(25),  # the model needs < 90 deg
    )
