"""ControlLoop's plumbing on the emulator's virtual clock: each revolution and frame reaches the
pilot with the pose at its own time, the command with the pose now, and the twist is driven."""

from __future__ import annotations

import pytest

from host_sdk import Robot
from host_sdk.autonomy import ControlLoop
from host_sdk.perception.tracking import Track
from host_sdk.pose import Pose
from host_sdk.sensors import CameraFrame, CameraSource, Lidar, LidarScan

URL = "emu://diffdrive-tb6612?clock=virtual&seed=2&world=random:2&lidar=rplidar-a1&camera=320x240"


class RecordingPilot:
    name = "recording"

    def __init__(self) -> None:
        self.scans: list[tuple[LidarScan, Pose]] = []
        self.frames: list[tuple[CameraFrame, Pose]] = []
        self.commands: list[Pose] = []

    def on_scan(self, scan: LidarScan, pose: Pose, *, pose_at: object = None) -> None:
        self.scans.append((scan, pose))

    def on_frame(self, frame: CameraFrame, pose: Pose) -> Track | None:
        self.frames.append((frame, pose))
        return None

    def command(self, pose: Pose) -> tuple[float, float, str]:
        self.commands.append(pose)
        return 0.2, 0.3, "turning"


def test_each_input_reaches_the_pilot_with_the_pose_at_its_own_time() -> None:
    with Robot.connect(URL, clamp=True) as robot:
        lidar = Lidar.open(robot.transport.endpoints["lidar"], "rplidar-a1")
        camera = CameraSource(robot.transport.endpoints["camera"])
        pilot = RecordingPilot()
        with ControlLoop(robot, pilot, lidar=lidar, camera=camera, arm=True) as loop:
            for _ in range(60):  # 3 s of 50 ms periods
                step = loop.step()
                loop.wait()
        lidar.close()
        camera.close()
        moved = robot.odometry.pose
    assert step.mode == "turning" and (step.linear_m_s, step.angular_rad_s) == (0.2, 0.3)
    assert moved.x_m > 0.2 and moved.theta_rad > 0.4  # the twist was driven
    assert len(pilot.scans) >= 10 and len(pilot.frames) >= 10
    for scan, pose in pilot.scans:
        assert pose.time_s == pytest.approx(scan.time_s + scan.duration_s / 2)
    for frame, pose in pilot.frames:
        assert pose.time_s == pytest.approx(frame.time_s)
    times = [pose.time_s for pose in pilot.commands]
    assert times == sorted(times) and times[-1] - times[0] == pytest.approx(59 * 0.05, abs=0.03)
    assert max(p.linear_m_s for p in pilot.commands) > 0.1  # the measured speed rides along
