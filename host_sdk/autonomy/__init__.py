"""Behaviour for robot programs: a control loop that feeds a pilot (`ControlLoop`, `Pilot`; `FollowPilot`
joins the pieces below up, ready for a robot program); follow a tracked target while avoiding
obstacles (`Follower`),
with the target picked out of the lidar scan by the camera's bearing (`locate_target`) and followed in
the scan while the camera does not have it (`TargetFinder`); the robot's manoeuvres are planned a
few seconds ahead to keep the target in the picture and keep out of its way (`ViewPlanner`); a
person's drive command kept short of what the lidar sees (`TeleopGuard`, `LidarGuard` on a lidar).

numpy, and OpenCV for the planner's distance field (the tracker that feeds it needs OpenCV too);
see docs/autonomy.md.
"""

from host_sdk.autonomy.finder import TargetFinder
from host_sdk.autonomy.follow import Decision, Follower
from host_sdk.autonomy.follow_params import FollowParams, Mode
from host_sdk.autonomy.guard import Guarded, GuardState, LidarGuard, TeleopGuard, explain_failsafe
from host_sdk.autonomy.loop import ControlLoop, Step
from host_sdk.autonomy.pilot import FollowPilot, Halting, Pilot, follow_gap
from host_sdk.autonomy.planner import PlanChoice, PlannerParams, ViewPlanner
from host_sdk.autonomy.target import TargetFix, locate_target

__all__ = [
    "ControlLoop",
    "Decision",
    "FollowParams",
    "FollowPilot",
    "Follower",
    "GuardState",
    "Guarded",
    "Halting",
    "LidarGuard",
    "Mode",
    "Pilot",
    "PlanChoice",
    "PlannerParams",
    "Step",
    "TargetFinder",
    "TargetFix",
    "TeleopGuard",
    "ViewPlanner",
    "explain_failsafe",
    "follow_gap",
    "locate_target",
]
