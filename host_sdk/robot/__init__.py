"""The robot as robot code holds it: `Robot` (robot.py) and the parts it is built from.

- `link`: the transport, session, runner, callbacks and lock, owned once (`Link`).
- `driving`, `feedback`, `settings`, `odometry`: the parts, each owning its state; their calls are
  Robot's (`forward.part_method`).
- `runner`: the I/O thread (or the inline runner on the emulator's virtual clock).
- `options`: connect()'s arguments checked; `file_check`: a board compared with a robot file;
  `callbacks`: the subscriber lists; `gains_watch`: the warning about gains that oscillate.
"""

from host_sdk.kinematics import KinematicsError
from host_sdk.robot.odometry import OdometryView
from host_sdk.robot.robot import Robot

__all__ = ["KinematicsError", "OdometryView", "Robot"]
