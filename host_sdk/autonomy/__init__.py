"""Behaviour for robot programs: follow a tracked target while avoiding obstacles (`Follower`),
with the target picked out of the lidar scan by the camera's bearing (`locate_target`).

numpy only (the tracker that feeds it needs OpenCV); see docs/autonomy.md.
"""

from host_sdk.autonomy.follow import Decision, Follower, FollowParams, Mode
from host_sdk.autonomy.target import TargetFix, locate_target

__all__ = ["Decision", "FollowParams", "Follower", "Mode", "TargetFix", "locate_target"]
