"""Recording and live view: an MCAP file and/or a Foxglove WebSocket server fed from a robot.

`Recorder.attach(robot, mcap_path=..., serve=..., sensors=...)` is the piece `roverlink record`,
`monitor --foxglove` and `follow --foxglove` share (`sensors`: a roverlink.sensors hub, whose lidar,
camera and IMU `SensorSource` records); `roverlink.recording.schemas` lists the topics and
schemas. Needs the `foxglove` extra (foxglove-sdk), imported when a recorder starts.
"""

from roverlink.recording.sensors import SensorSource
from roverlink.recording.sink import FoxgloveSink, Publisher, TimeBase
from roverlink.recording.sources import Recorder, RecordingSummary, RobotSource, Source, link_rates

__all__ = [
    "FoxgloveSink",
    "Publisher",
    "Recorder",
    "RecordingSummary",
    "RobotSource",
    "SensorSource",
    "Source",
    "TimeBase",
    "link_rates",
]
