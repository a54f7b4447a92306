"""The follower's tunables (`FollowParams`), its modes, the thresholds its steps share and the small
pieces of state it remembers between steps (host_sdk.autonomy.follow)."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from host_sdk.autonomy.planner import PlannerParams

MIN_DRIVE_M_S = 0.02
"""A commanded speed below this is not driven: there is no room to move on that way (stand, or do
something else)."""
MIN_LEG_M_S = 0.05
"""Ackermann K-turn: a leg whose safe speed falls below this is at its end."""
SPIN_CLEARANCE_M = 0.03
"""Room kept round the disc a differential drive sweeps turning in place."""
UNSTICK_M_S = 0.15
"""Speed of the straight move away from something too close to turn in place."""
BACK_OUT_ROOM_M = 0.25
"""Ackermann: room a reverse arc needs behind to back out on it..."""
PULL_OUT_ROOM_M = 0.35
"""...and a forward arc ahead to pull out on it instead."""
MANOEUVRE_SPEED_SHARE = 0.6
"""Backing or pulling out runs at this share of the reverse speed."""
STEP_OFF_S = 1.5
"""How long the search first steps off the lost target's route."""
LOOK_AHEAD_S = 8.0
"""How far ahead the search predicts where the lost target went."""
GO_THERE_M = 0.8
"""The search drives to where the target went when that is farther than this."""
WANDER_S = 8.0
"""How long the search spends getting to another place to look from..."""
WANDER_M = 1.5
"""...that far into the most open direction (or where it was last seen, if over WANDER_FAR_M away)."""
WANDER_FAR_M = 1.0
WANDER_ARRIVED_M = 0.5
WANDER_SPIN_RAD = 0.6
"""Differential drive: a place to look from more than this off the heading is turned to on the spot."""


@dataclass(frozen=True, slots=True)
class Manoeuvre:
    """Backing out (or, blocked behind, pulling out) on one arc until a time."""

    until_s: float
    curvature: float
    direction: float
    """+1 forwards, -1 backwards."""


@dataclass(frozen=True, slots=True)
class Aim:
    """A heading (odometry frame) to hold until a time: a step off the target's route."""

    until_s: float
    heading_rad: float


@dataclass(frozen=True, slots=True)
class Place:
    """A place (odometry frame) to go and look from, until a time."""

    until_s: float
    x_m: float
    y_m: float


class Mode(Enum):
    SEARCH = "search"
    TRACK = "track"
    AVOID = "avoid"
    YIELD = "yield"
    STOP = "stop"
    RECOVER = "recover"


@dataclass(frozen=True, slots=True)
class FollowParams:
    follow_gap_m: float = 0.5
    """Wanted gap between the robot's footprint and the target's surface."""
    max_speed_m_s: float = 0.45
    reverse_speed_m_s: float = 0.35
    gain_turn: float = 2.5
    """Differential drive, searching: turn rate per radian of heading error, 1/s."""
    max_turn_rate: float = 1.6
    coast_s: float = 1.5
    """How long a lost target is still taken to be where it is predicted (and followed there)."""
    hold_s: float = 0.6
    """Having begun to move forwards (or backwards), the planner keeps that way this long: choosing
    again 20 times a second, a car chattered between the two and never moved."""
    go_s: float = 0.3
    """Ackermann: having started from standing, it keeps moving for this long (unless that runs into
    the target). A differential drive stands to turn, so it is not held to going."""
    look_s: float = 5.0
    """How long after that the planner still looks where it is predicted to be, before the search
    turns round to look for it."""
    doubt_s: float = 1.0
    """The target followed in the scan alone is dropped when the camera, looking straight at it, has
    not seen it for this long (the cluster followed is something else)."""
    reject_s: float = 5.0
    """How long a place so found not to be the target is not taken for it again."""
    confirm_s: float = 8.0
    """A mover followed this long without the camera confirming it is dropped too..."""
    keep_near_m: float = 1.0
    """...unless it is this close (a moving body that near is one to keep clear of)."""
    search_speed_m_s: float = 0.25
    search_turn_rate: float = 0.9
    """Differential drive: turn rate while searching."""
    k_turn_leg_m: float = 0.4
    """Ackermann: length of each leg of the K-turn it searches with."""
    blocked_s: float = 0.6
    """Ackermann: blocked this long while searching, it backs out."""
    recover_s: float = 1.2
    target_size_m: float = 0.3
    """About how wide the target is (to pick its returns out of the scan)."""
    planner: PlannerParams | None = None
    """The manoeuvre planner's weights and limits (default: `PlannerParams` with the speeds above)."""
