"""Perception for robot programs: lidar scan processing, obstacle avoidance and camera tracking.

- `scan`: any lidar scan (the SDK's drivers, ROS LaserScan-shaped messages, arrays) to a filtered
  360-degree obstacle picture around the robot (`ScanFilter`, `ObstacleScan`).
- `avoidance`: the footprint's swept corridor, free directions over the whole scan, the speed law
  (`Avoider`, `Footprint`, `AvoidanceParams`).
- `motion`: what moves in the scan (`MotionDetector`, `Mover`): returns where earlier revolutions
  saw free space, clustered and confirmed.
- `CameraModel`, `Footprint`, `LidarMount` (from host_sdk.body, re-exported): the camera's
  pinhole model, the body's disc and the lidar's mount, which a robot file describes.
- `tracking`: a fast template tracker with feature re-detection (`Tracker`, `Track`, `TrackState`);
  it needs OpenCV (the `vision` extra), imported when a tracker is made. `appearance`: its model of
  the object (the template's core, an adaptive copy anchored to the first, a colour signature);
  `template`: template files (`read_template`: a PNG with a transparent background is a cut-out).
- `detectors`, `class_tracker` (imported from their modules): people (HOG) and faces (Haar cascades)
  in a frame, and a person or a face followed by the tracker and found again by the detector
  (`ClassTracker`); OpenCV 4.

numpy is the only import here; see docs/autonomy.md.
"""

from host_sdk.body import CameraModel, Footprint, LidarMount
from host_sdk.perception.avoidance import AvoidanceParams, Avoider, Plan
from host_sdk.perception.motion import MotionDetector, MotionParams, Mover
from host_sdk.perception.scan import ObstacleScan, RawScan, ScanFilter
from host_sdk.perception.tracker_params import TrackerParams
from host_sdk.perception.tracking import Track, Tracker, TrackState

__all__ = [
    "AvoidanceParams",
    "Avoider",
    "CameraModel",
    "Footprint",
    "LidarMount",
    "MotionDetector",
    "MotionParams",
    "Mover",
    "ObstacleScan",
    "Plan",
    "RawScan",
    "ScanFilter",
    "Track",
    "TrackState",
    "Tracker",
    "TrackerParams",
]
