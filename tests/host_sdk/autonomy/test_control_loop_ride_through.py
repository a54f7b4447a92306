"""ControlLoop rides through the robot's failures (virtual clock): a cut link or a board reset halts the
pilot and clears its command, nothing is driven while the link is down, the robot is armed again only
with rearm=True; a sensor that fails is reported and the loop goes on."""

from __future__ import annotations

from urllib.parse import quote

from host_sdk import Robot
from host_sdk.autonomy import ControlLoop, Step
from host_sdk.perception.tracking import Track
from host_sdk.pose import Pose
from host_sdk.sensors import CameraFrame, CameraSource, Lidar, LidarScan

URL = "emu://diffdrive-tb6612?clock=virtual&seed=2&world=random:2&lidar=rplidar-a1&camera=320x240"


class HaltingPilot:
    name = "halting"

    def __init__(self) -> None:
        self.halts: list[tuple[float, str]] = []
        self.now = 0.0

    def on_scan(self, scan: LidarScan, pose: Pose, *, pose_at: object = None) -> None:
        pass

    def on_frame(self, frame: CameraFrame, pose: Pose) -> Track | None:
        return None

    def command(self, pose: Pose) -> tuple[float, float, str]:
        self.now = pose.time_s
        return 0.1, 0.0, "creeping"

    def halt(self, why: str) -> None:
        self.halts.append((self.now, why))


def run(faults: str, seconds: float, *, rearm: bool = False) -> tuple[list[Step], HaltingPilot, ControlLoop]:
    with Robot.connect(f"{URL}&faults={quote(faults)}", clamp=True) as robot:
        lidar = Lidar.open(robot.transport.endpoints["lidar"], "rplidar-a1")
        camera = CameraSource(robot.transport.endpoints["camera"])
        pilot = HaltingPilot()
        steps = []
        with ControlLoop(robot, pilot, lidar=lidar, camera=camera, arm=True, rearm=rearm) as loop:
            while robot.now() - loop.started_s < seconds:
                steps.append(loop.step())
                loop.wait()
        lidar.close()
        camera.close()
    return steps, pilot, loop


def test_a_cut_link_halts_the_pilot_and_nothing_drives_until_the_user_arms() -> None:
    steps, pilot, loop = run("cut@2-3", 5.0)
    assert pilot.halts and 2.0 < pilot.halts[0][0] < 3.0 and pilot.halts[0][1] == "link lost"
    down = [s for s in steps if s.health.link != "up"]
    assert down and not any(s.driven for s in down)
    after = [s for s in steps if s.pose.time_s > 3.5]
    assert after and not any(s.driven or s.health.armed for s in after)  # rearm=False: it stays disarmed
    assert after[-1].health.failsafe == "COMM_TIMEOUT" and loop.failsafes == 1


def test_with_rearm_the_loop_arms_again_after_a_reset() -> None:
    steps, pilot, _ = run("reset@2", 6.0, rearm=True)
    assert any(why == "board reset" for _, why in pilot.halts)
    assert steps[-1].driven and steps[-1].health.armed and steps[-1].health.reset is None


def test_a_lidar_that_fails_is_reported_and_the_loop_goes_on() -> None:
    with Robot.connect(URL, clamp=True) as robot:
        lidar = Lidar.open(robot.transport.endpoints["lidar"], "rplidar-a1")
        camera = CameraSource(robot.transport.endpoints["camera"])
        with ControlLoop(robot, HaltingPilot(), lidar=lidar, camera=camera, arm=True) as loop:
            loop.step()
            lidar.port.close()  # unplugged
            for _ in range(5):
                step = loop.step()
                loop.wait()
        camera.close()
    assert "lidar" in loop.sensor_errors and step.driven
