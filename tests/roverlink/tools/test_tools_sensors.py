"""The sensors in the tools: recorded (MCAP read back, the live view), shown by the monitor, named
on the command line; against an emulated robot with a world, a lidar, the IMU and the camera."""

from __future__ import annotations

import argparse
import asyncio
import math
import re
from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np
import pytest
from mcap_support import LiveClient, open_live, read_mcap
from textual_pilot import until

from host_sdk import Robot
from host_sdk.recording import Recorder
from host_sdk.recording.schemas import TOPIC_IMAGE, TOPIC_IMU, TOPIC_SCAN, TOPIC_TF, imu_message
from host_sdk.recording.sensors import laser_scan_fields
from host_sdk.sensors import CameraFrame, ImuSample, LidarScan, Sensors
from protocol.generated.profiles import ROBOT_SENSORS
from roverlink.cli import main
from roverlink.dashboard import Dashboard
from roverlink.sensors import SensorChoice, choose_sensors, open_sensors
from roverlink.tui import DashboardApp
from tests.support.emulate import ROOM, SENSOR_ROBOT_ARGS, emulate

SENSORS = "lidar=rplidar-a1&imu=jy901&camera=1"
URL = f"emu://diffdrive-bts7960?clock=virtual&seed=5&world={ROOM}&{SENSORS}"


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


class Seen:
    """Everything the drivers delivered, through the hub's listeners."""

    def __init__(self, sensors: Sensors) -> None:
        self.scans: list[LidarScan] = []
        self.imu: list[ImuSample] = []
        self.frames: list[CameraFrame] = []
        sensors.on_scan(self.scans.append)
        sensors.on_imu(self.imu.append)
        sensors.on_frame(self.frames.append)


def _drive_circle(robot: Robot, recorder: Recorder, seconds: float) -> list[tuple[float, float]]:
    """Drive a circle, polling the recorder every feedback period; (time, true heading) on the way."""
    headings = []
    end = robot.now() + seconds
    while robot.now() < end:
        robot.drive(0.2, 0.6)
        robot.wait_feedback()
        recorder.poll()
        headings.append((robot.now(), robot.emulator.truth.world.theta_rad))
    return headings


def test_sensor_recording_reads_back_as_the_drivers_saw_it(tmp_path: Path) -> None:
    path = tmp_path / "sensors.mcap"
    with Robot.connect(URL) as robot, open_sensors(choose_sensors(argparse.Namespace(), robot)) as sensors:
        assert sensors.kinds() == ["lidar", "imu", "camera"]
        seen = Seen(sensors)
        with Recorder.attach(robot, mcap_path=path, sensors=sensors) as recorder:
            robot.arm()
            truth = _drive_circle(robot, recorder, 2.5)
        status = sensors.status()
        dropped = sensors.camera.dropped if sensors.camera is not None else -1
    rec = read_mcap(path)
    assert rec.schemas[TOPIC_SCAN] == ("foxglove.LaserScan", "protobuf")
    assert rec.schemas[TOPIC_IMAGE] == ("foxglove.CompressedImage", "protobuf")
    assert rec.schemas[TOPIC_IMU] == ("roverlink.Imu", "jsonschema")

    # Every revolution, frame and IMU period the drivers delivered, once, in order.
    assert rec.counts[TOPIC_SCAN] == len(seen.scans) >= 12  # 5.5 Hz
    assert rec.counts[TOPIC_IMAGE] == len(seen.frames) >= 75  # 30 fps
    assert rec.counts[TOPIC_IMU] == len(seen.imu) >= 500  # 200 Hz
    assert dropped == 0 and status.errors == ()

    # Scans: the nearest return per degree, as the driver's own scan bins them.
    for (_, msg), scan in zip(rec.messages[TOPIC_SCAN], seen.scans, strict=True):
        fields = laser_scan_fields(scan)
        assert msg.frame_id == "laser" and len(msg.ranges) == 360
        np.testing.assert_array_equal(np.array(msg.ranges), fields["ranges"])
        np.testing.assert_array_equal(np.array(msg.intensities), fields["intensities"])
        assert (msg.start_angle, msg.end_angle) == pytest.approx((-math.pi, math.pi - math.radians(1)))
        assert np.isfinite(msg.ranges).mean() > 0.85
    first_ns = rec.messages[TOPIC_SCAN][0][0]
    assert (rec.messages[TOPIC_SCAN][-1][0] - first_ns) / 1e9 == pytest.approx(
        seen.scans[-1].time_s - seen.scans[0].time_s, abs=1e-6
    )

    # Frames: the stream's own JPEG bytes, which decode to the driver's image.
    for (_, msg), frame in zip(rec.messages[TOPIC_IMAGE], seen.frames, strict=True):
        assert msg.format == "jpeg" and msg.frame_id == "camera" and msg.data == frame.jpeg
    last = cv2.imdecode(np.frombuffer(rec.messages[TOPIC_IMAGE][-1][1].data, np.uint8), cv2.IMREAD_COLOR)
    np.testing.assert_array_equal(last, seen.frames[-1].image)

    # IMU: every field as decoded; and it saw the robot turn (the yaw follows the true heading).
    recorded = [m for _, m in rec.messages[TOPIC_IMU]]
    assert recorded == [imu_message(s) for s in seen.imu]
    assert all(m["linear_acceleration"][2] == pytest.approx(9.81, abs=0.3) for m in recorded[::50])
    t_end, heading = truth[-1]
    yaw = next(s for s in reversed(seen.imu) if s.t <= t_end).angle
    assert yaw is not None and abs(_wrap(yaw[2] - heading)) < 0.2  # the uncalibrated compass's few degrees
    turning = [m["angular_velocity"][2] for m in recorded[len(recorded) // 2 :]]
    assert float(np.mean(turning)) == pytest.approx(0.6 * 0.95, rel=0.1)  # the commanded 0.6 rad/s

    # Where the sensors sit on the robot, for the 3D view.
    children = {tf.child_frame_id: tf for _, m in rec.messages[TOPIC_TF] for tf in m.transforms}
    mount = ROBOT_SENSORS["diffdrive-bts7960"].mount("lidar")
    assert mount is not None
    laser = children["laser"]
    assert (laser.parent_frame_id, laser.translation.z) == ("base_link", pytest.approx(mount.z_m))
    assert {"laser", "imu", "camera", "base_link"} <= set(children)


def test_live_view_serves_scans_images_and_imu() -> None:
    with Robot.connect(URL) as robot, open_sensors(choose_sensors(argparse.Namespace(), robot)) as sensors:
        recorder = Recorder.attach(robot, serve=True, port=0, sensors=sensors)
        port = recorder.sink.port
        assert port is not None
        topics = (TOPIC_SCAN, TOPIC_IMAGE, TOPIC_IMU)

        def step() -> None:
            robot.sleep(0.05)
            recorder.poll()

        with open_live(port) as ws:
            client = LiveClient(ws)
            assert client.wait_for(lambda: set(topics) <= set(client.channels), step)
            client.subscribe(*topics)
            assert client.wait_for(lambda: all(len(client.received[t]) >= 2 for t in topics), step)
        recorder.close()
    scan = client.received[TOPIC_SCAN][-1][1]
    assert scan.frame_id == "laser" and len(scan.ranges) == 360 and np.isfinite(scan.ranges).mean() > 0.85
    image = client.received[TOPIC_IMAGE][-1][1]
    assert image.format == "jpeg" and image.data[:2] == b"\xff\xd8"
    assert cv2.imdecode(np.frombuffer(image.data, np.uint8), cv2.IMREAD_COLOR).shape == (240, 320, 3)
    imu = client.received[TOPIC_IMU][-1][1]
    assert imu["frame_id"] == "imu" and imu["linear_acceleration"][2] == pytest.approx(9.81, abs=0.3)


def test_record_command_takes_the_devices_the_url_attached(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    url = f"emu://picar?clock=virtual&seed=2&world={ROOM}&lidar=ydlidar-f4&imu=jy901&camera=1"
    path = tmp_path / "cli.mcap"
    assert main(["record", url, "-o", str(path), "--duration", "1.5"]) == 0
    out = capsys.readouterr().out
    assert "with the lidar ydlidar-f4 on emudev://" in out and "with the camera emudev://" in out
    counts = read_mcap(path).counts
    assert 10 <= counts[TOPIC_SCAN] <= 13  # 8 Hz
    assert 42 <= counts[TOPIC_IMAGE] <= 46 and 290 <= counts[TOPIC_IMU] <= 305
    assert main(["record", url, "-o", str(tmp_path / "none.mcap"), "--duration", "0.5", "--no-sensors"]) == 0
    assert TOPIC_SCAN not in read_mcap(tmp_path / "none.mcap").counts


# The robot faces a box 0.6 m ahead of its lidar; the walls are at least 1.5 m away.
FACING_A_BOX = """
[world]
size_m = [6.0, 4.0]
[start]
x_m = 3.0
y_m = 2.0
theta_deg = 0.0
[[boxes]]
center = [3.7, 2.0]
size = [0.2, 1.0]
"""


def test_monitor_shows_the_sensors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    world = tmp_path / "box.toml"
    world.write_text(FACING_A_BOX, encoding="utf-8")
    url = f"emu://diffdrive-bts7960?clock=virtual&seed=1&world={world}&{SENSORS}"
    assert main(["monitor", url, "--plain", "--duration", "2"]) == 0
    out = capsys.readouterr().out
    lidar = re.search(r"lidar +rplidar-a1 +([\d.]+) scans/s +(\d+) points .* nearest ([\d.]+) m at ([+-]\d+) deg", out)
    assert lidar is not None, out
    rate, points, nearest, bearing = float(lidar[1]), int(lidar[2]), float(lidar[3]), int(lidar[4])
    assert rate == pytest.approx(5.5, rel=0.03) and 340 < points < 390
    # The box's face is flat: within noise (3 mm at 0.6 m) the nearest return is any of a few degrees.
    assert nearest == pytest.approx(0.6, abs=0.012) and abs(bearing) <= 10
    imu = re.search(r"imu +(\d+) Hz +roll ([+-][\d.]+) +pitch ([+-][\d.]+) +yaw ([+-][\d.]+) deg", out)
    assert imu is not None, out
    assert float(imu[1]) == pytest.approx(200, rel=0.1) and abs(float(imu[4])) < 6  # facing +x: yaw 0
    camera = re.search(r"camera +320x240 +([\d.]+) fps +(\d+) frames +dropped (\d+)", out)
    assert camera is not None, out
    assert float(camera[1]) == pytest.approx(30, rel=0.02) and int(camera[2]) >= 55 and camera[3] == "0"
    assert re.search(r"scan 5\.\d/s near 0\.6\dm  yaw [+-]\d+\.\d  cam 30fps drop 0", out)


def test_a_device_that_cannot_open_is_named(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code = main(["record", "emu://picar?clock=virtual", "-o", str(tmp_path / "x.mcap"), "--lidar", "/dev/nonexistent"])
    assert code == 1
    # Named with its model: the PiCar's own lidar, a YDLIDAR F4, by default.
    assert "roverlink record: lidar ydlidar-f4 on /dev/nonexistent: could not open" in capsys.readouterr().err


@pytest.fixture(scope="module")
def served() -> Iterator[tuple[str, dict[str, str]]]:
    """A robot on a serial port with its sensors on theirs, as real ones appear: `roverlink emulate`
    serves the board and each device on a pty of its own, the camera over HTTP."""
    args = SENSOR_ROBOT_ARGS
    with emulate(*args, devices=3) as served:
        yield served.url, {name: words[-1] for name, words in served.devices.items()}


def test_record_names_real_ports_on_the_command_line(
    served: tuple[str, dict[str, str]], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Each device named with its option and read by a thread of its own."""
    board, port = served
    path = tmp_path / "ports.mcap"
    args = ["--lidar", port["lidar"], "--imu", port["imu"], "--camera", port["camera"]]
    assert main(["record", board, "-o", str(path), "--duration", "2", *args]) == 0
    out = capsys.readouterr().out
    assert f"with the lidar rplidar-a1 on {port['lidar']}" in out  # the model: the robot profile's lidar
    rec = read_mcap(path)
    assert rec.counts[TOPIC_SCAN] >= 6 and rec.counts[TOPIC_IMU] >= 200 and rec.counts[TOPIC_IMAGE] >= 20
    scan = rec.messages[TOPIC_SCAN][-1][1]
    assert np.isfinite(scan.ranges).mean() > 0.85
    image = cv2.imdecode(np.frombuffer(rec.messages[TOPIC_IMAGE][-1][1].data, np.uint8), cv2.IMREAD_COLOR)
    assert image.shape == (240, 320, 3)
    # Stamped on arrival by each thread: the IMU's periods spread over the recording, not in bursts.
    imu_times = np.array([t for t, _ in rec.messages[TOPIC_IMU]]) / 1e9
    assert np.diff(imu_times).max() < 0.2 and imu_times[-1] - imu_times[0] > 1.5


def test_textual_monitor_shows_the_sensors(served: tuple[str, dict[str, str]]) -> None:
    board, port = served
    choice = SensorChoice(lidar=port["lidar"], lidar_model="rplidar-a1", imu=port["imu"], camera=port["camera"])
    with Robot.connect(board) as robot, open_sensors(choice) as sensors:
        sensors.start()
        app = DashboardApp(Dashboard(robot, sensors=sensors), hz=10)

        def text() -> str:
            return str(app.query_one("#sensors").render())

        async def run() -> str:
            async with app.run_test() as pilot:
                assert await until(lambda: re.search(r"nearest [\d.]+ m", text()) is not None, pilot)
                assert await until(lambda: re.search(r"320x240 +[\d.]+ fps", text()) is not None, pilot)
                shown = text()
                await pilot.press("q")
                return shown

        shown = asyncio.run(run())
    assert "rplidar-a1" in shown and "scans/s" in shown and "yaw" in shown and "dropped" in shown
