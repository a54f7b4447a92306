"""`roverlink record` and the recording library: MCAP files read back, and the live WebSocket view."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from mcap_support import LiveClient, open_live, read_mcap

from host_sdk import FeedbackSample, Robot, SessionResetError
from host_sdk.enums import LogLevel
from host_sdk.recording import Publisher, Recorder
from host_sdk.recording.schemas import (
    FEEDBACK_SCHEMA,
    IMU_SCHEMA,
    TOPIC_FEEDBACK,
    TOPIC_IMAGE,
    TOPIC_IMU,
    TOPIC_LINK,
    TOPIC_LOG,
    TOPIC_ODOMETRY,
    TOPIC_PATH,
    TOPIC_SCAN,
    TOPIC_TF,
    TOPIC_WHEELS,
    feedback_message,
)
from roverlink.cli import main

PROFILES = ["diffdrive-tb6612", "diffdrive-bts7960", "picar"]


def _drive(robot: Robot, steps: int) -> None:
    for _ in range(steps):
        if robot.kinematics is not None and hasattr(robot.kinematics, "track_m"):
            robot.drive(0.3, 0.8)
        else:
            robot.drive_ackermann(0.5, 0.25)
        robot.wait_feedback()


@pytest.mark.parametrize("profile", PROFILES)
def test_recording_reads_back_as_the_sdk_saw_it(tmp_path: Path, profile: str) -> None:
    path = tmp_path / "run.mcap"
    seen: list[FeedbackSample] = []
    logs: list[tuple[LogLevel, str]] = []
    # eeprom=blank: every boot runs on defaults and says so in a LOG(WARN) line; the board is
    # reset once the recorder runs, so the recording holds a LOG line and a session change.
    with Robot.connect(f"emu://{profile}?clock=virtual&eeprom=blank&seed=3") as robot:
        robot.on_feedback(seen.append)
        robot.on_log(lambda level, text: logs.append((level, text)))
        recorder = Recorder.attach(robot, mcap_path=path)
        boot = robot.identity.boot_id
        robot.emulator.reset_mcu()
        for _ in range(100):  # the bootloader, the boot announcement, a new session
            robot.sleep(0.05)
            if robot.state == "disarmed" and robot.identity.boot_id != boot:
                break
        with pytest.raises(SessionResetError):  # the first call to meet the reset reports it, once
            robot.arm()
        robot.arm()
        for _ in range(6):
            _drive(robot, 25)
            recorder.poll()
        robot.sleep(1.1)  # the link statistics interval
        recorder.poll()
        summary = recorder.close()
    assert summary.path == path and summary.bytes == path.stat().st_size > 0
    rec = read_mcap(path)

    assert rec.schemas[TOPIC_FEEDBACK] == ("roverlink.Feedback", "jsonschema")
    assert rec.schemas[TOPIC_WHEELS] == ("roverlink.Wheels", "jsonschema")
    assert rec.schemas[TOPIC_LINK] == ("roverlink.LinkStats", "jsonschema")
    assert rec.schemas[TOPIC_ODOMETRY] == ("foxglove.PoseInFrame", "protobuf")
    assert rec.schemas[TOPIC_PATH] == ("foxglove.PosesInFrame", "protobuf")
    assert rec.schemas[TOPIC_TF] == ("foxglove.FrameTransforms", "protobuf")
    assert rec.schemas[TOPIC_LOG] == ("foxglove.Log", "protobuf")
    assert rec.counts == summary.counts

    # Every FEEDBACK the SDK saw after the recorder started, in order, with every field.
    recorded = [m for _, m in rec.messages[TOPIC_FEEDBACK]]
    first = recorded[0]["index"]
    expected = [feedback_message(s) for s in seen if s.index >= first]
    assert len(recorded) == len(expected) == rec.counts[TOPIC_FEEDBACK] > 150
    assert recorded == expected
    assert set(FEEDBACK_SCHEMA["properties"]) == set(recorded[0])

    # Odometry and the transform follow the pose the SDK computed; the path ends where the robot is.
    poses = [(s.pose.x_m, s.pose.y_m, s.pose.theta_rad) for s in seen if s.index >= first and s.pose]
    odom = [m.pose for _, m in rec.messages[TOPIC_ODOMETRY]]
    assert len(odom) == len(poses)
    for msg, (x, y, theta) in zip(odom, poses, strict=True):
        assert (msg.position.x, msg.position.y) == pytest.approx((x, y))
        assert 2 * math.atan2(msg.orientation.z, msg.orientation.w) == pytest.approx(
            math.remainder(theta, 2 * math.tau)
        )
    tf = rec.messages[TOPIC_TF][-1][1].transforms[0]
    assert (tf.parent_frame_id, tf.child_frame_id) == ("odom", "base_link")
    assert tf.translation.x == pytest.approx(poses[-1][0])
    path_msg = rec.messages[TOPIC_PATH][-1][1]
    assert path_msg.poses[-1].position.x == pytest.approx(poses[-1][0], abs=0.03)
    assert math.hypot(poses[-1][0], poses[-1][1]) > 0.3

    # LOG lines as the SDK got them; link statistics from both sides.
    assert len(logs) == 1  # the reset's boot (the first boot's line came before on_log)
    assert [m.message for _, m in rec.messages[TOPIC_LOG]] == [text for _, text in logs]
    assert rec.messages[TOPIC_LOG][0][1].level == 3  # foxglove.Log WARNING
    link = rec.messages[TOPIC_LINK][-1][1]
    assert link["host"]["feedback_received"] >= len(recorded)
    assert link["board"]["frames_ok"] > 0
    assert link["rates"]["feedback_received_per_s"] > 10

    # Log times follow the robot's clock: the recording spans what was driven.
    times = [t for t, _ in rec.messages[TOPIC_FEEDBACK]]
    assert times == sorted(times)
    assert (times[-1] - times[0]) / 1e9 == pytest.approx(
        seen[-1].host_time_s - expected_first_time(seen, first), abs=0.05
    )


def expected_first_time(seen: list[FeedbackSample], first: int) -> float:
    return next(s.host_time_s for s in seen if s.index == first)


def test_record_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "cli.mcap"
    assert main(["record", "emu://picar?clock=virtual", "-o", str(path), "--duration", "2"]) == 0
    out = capsys.readouterr().out
    assert "recorded" in out and "/roverlink/feedback" in out
    rec = read_mcap(path)
    # 2 s at the 50 Hz the command asks for (the first sample may fall either side of the edges).
    assert 95 <= rec.counts[TOPIC_FEEDBACK] <= 102
    assert rec.counts[TOPIC_LINK] >= 2
    assert main(["record", "emu://picar?clock=virtual", "-o", str(path), "--duration", "1"]) == 1
    assert "exists" in capsys.readouterr().err
    assert main(["record", "emu://picar?clock=virtual", "-o", str(path), "--duration", "1", "--force"]) == 0
    assert main(["record", "emu://picar?clock=virtual", "-o", str(tmp_path / "x.txt")]) == 2


def test_live_view_serves_decodable_messages() -> None:
    with Robot.connect("emu://diffdrive-tb6612?clock=virtual") as robot:
        recorder = Recorder.attach(robot, serve=True, port=0)
        port = recorder.sink.port
        assert port is not None and recorder.sink.url == f"ws://127.0.0.1:{port}"
        with open_live(port) as ws:
            client = LiveClient(ws)
            robot.arm()
            step = lambda: _drive(robot, 1)  # noqa: E731
            # Channels are advertised once something was published on them.
            assert client.wait_for(lambda: {TOPIC_FEEDBACK, TOPIC_ODOMETRY} <= set(client.channels), step)
            client.subscribe(TOPIC_FEEDBACK, TOPIC_ODOMETRY)
            assert client.wait_for(
                lambda: len(client.received[TOPIC_FEEDBACK]) >= 5 and len(client.received[TOPIC_ODOMETRY]) >= 5, step
            )
        recorder.close()
    feedback = [m for _, m in client.received[TOPIC_FEEDBACK]]
    assert [m["index"] for m in feedback] == sorted(m["index"] for m in feedback)
    assert feedback[-1]["status_flags"] == ["SESSION", "ARMED"]
    odom = client.received[TOPIC_ODOMETRY][-1][1]
    assert odom.frame_id == "odom" and odom.pose.position.x > 0


def test_shipped_layout_is_current_and_names_recorded_topics() -> None:
    from host_sdk.recording.layout import layout_json

    shipped = Path(__file__).resolve().parents[3] / "docs" / "foxglove-layout.json"
    assert shipped.read_text(encoding="utf-8") == layout_json(), "regenerate: python -m host_sdk.recording.layout"
    text = shipped.read_text(encoding="utf-8")
    for topic in (TOPIC_ODOMETRY, TOPIC_PATH, TOPIC_WHEELS, TOPIC_LINK, TOPIC_LOG, TOPIC_FEEDBACK):
        assert f'"{topic}' in text
    # The scan in the 3D panel, the camera in an image panel, the IMU's yaw in a plot.
    assert f'"{TOPIC_SCAN}": {{' in text and f'"imageTopic": "{TOPIC_IMAGE}"' in text
    assert f'"{TOPIC_IMU}.angles_rad[2]"' in text


class _FakeSensors:
    """A source shaped like the sensor drivers will be: a scan, a JPEG and an IMU sample per poll."""

    name = "sensors"

    def __init__(self) -> None:
        self.out: Publisher | None = None
        self.polls = 0

    def start(self, out: Publisher) -> None:
        self.out = out

    def poll(self, now_s: float) -> None:
        assert self.out is not None
        self.polls += 1
        ranges = [1.0 + 0.01 * i for i in range(360)]
        self.out.laser_scan(
            TOPIC_SCAN, now_s, frame_id="laser", start_angle=0.0, end_angle=2 * math.pi, ranges=ranges, intensities=[]
        )
        self.out.compressed_image(TOPIC_IMAGE, now_s, frame_id="camera", fmt="jpeg", data=b"\xff\xd8fake\xff\xd9")
        imu = {
            "frame_id": "imu",
            "orientation": [0, 0, 0, 1],
            "angular_velocity": [0, 0, 0.1],
            "linear_acceleration": [0, 0, 9.81],
        }
        self.out.json(TOPIC_IMU, IMU_SCHEMA, imu, now_s)

    def stop(self) -> None:
        self.out = None


def test_sensor_sources_record_with_foxglove_schemas(tmp_path: Path) -> None:
    path = tmp_path / "sensors.mcap"
    sensors = _FakeSensors()
    with (
        Robot.connect("emu://picar?clock=virtual") as robot,
        Recorder.attach(robot, mcap_path=path, sources=[sensors], board_stats=False) as recorder,
    ):
        for _ in range(5):
            robot.sleep(0.1)
            recorder.poll()
    rec = read_mcap(path)
    assert rec.schemas[TOPIC_SCAN] == ("foxglove.LaserScan", "protobuf")
    assert rec.schemas[TOPIC_IMAGE] == ("foxglove.CompressedImage", "protobuf")
    assert rec.schemas[TOPIC_IMU] == ("roverlink.Imu", "jsonschema")
    assert rec.counts[TOPIC_SCAN] == rec.counts[TOPIC_IMAGE] == rec.counts[TOPIC_IMU] == sensors.polls == 5
    scan = rec.messages[TOPIC_SCAN][-1][1]
    assert scan.frame_id == "laser" and len(scan.ranges) == 360 and scan.ranges[10] == pytest.approx(1.1)
    assert rec.messages[TOPIC_IMAGE][0][1].data == b"\xff\xd8fake\xff\xd9"
    assert rec.messages[TOPIC_IMU][0][1]["linear_acceleration"] == [0, 0, 9.81]
