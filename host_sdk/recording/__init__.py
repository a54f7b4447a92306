"""Recording and live view: an MCAP file and/or a Foxglove WebSocket server fed from a robot.

`Recorder.attach(robot, mcap_path=..., serve=..., sensors=...)` is the piece `roverlink record`,
`monitor --foxglove` and `follow --foxglove` share, and a robot program's own (`sensors`: a
`host_sdk.sensors.Sensors` hub, whose lidar, camera and IMU `SensorSource` records);
`host_sdk.recording.schemas` lists the topics and schemas. Needs the `foxglove` extra
(foxglove-sdk), imported when a recorder starts.
"""

from host_sdk.recording.sensors import SensorSource
from host_sdk.recording.sink import FoxgloveSink, Publisher, TimeBase
from host_sdk.recording.sources import Recorder, RecordingSummary, RobotSource, Source, link_rates

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
