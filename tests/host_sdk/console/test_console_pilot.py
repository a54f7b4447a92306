"""The console's pilot: a target chosen on the page is the one tracked, on the frame it was chosen
on; a person clicked among several is that person. Real photos (tests/data/photos, OpenCV's street
clip) and real OpenCV; the robot is a stand-in holding only what the pilot reads of it."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

from host_sdk.console.hub import Drive, Hub, Select
from host_sdk.console.pilot import ConsolePilot
from host_sdk.geometry import geometry
from host_sdk.perception.class_tracker import ClassTracker
from host_sdk.perception.detectors import iou
from host_sdk.pose import Pose
from host_sdk.sensors import CameraFrame, LidarScan
from tests.host_sdk.autonomy.photos import PERSONS, needs_detectors, photo

cv2 = pytest.importorskip("cv2")
FPS = 15.0


class StandIn:
    """What the pilot reads of a robot (through its supervisor): armed, failsafe, link state and
    counters, the clock, the callbacks it subscribes."""

    armed = False
    failsafe = None
    state = "disarmed"
    stats = SimpleNamespace(crc_errors=0, cobs_errors=0, length_errors=0, seq_gaps=0, feedback_received=0, rtt=None)
    url = "stand-in"
    feedback_age_s = None
    identity = SimpleNamespace(feedback_hz=50)

    def arm(self, timeout_s: float = 2.0) -> None:
        self.armed = True

    def now(self) -> float:
        return 0.0

    def on_reset(self, callback: Any) -> Any:
        return lambda: None

    on_failsafe = on_reset


def pilot() -> tuple[ConsolePilot, Hub]:
    hub = Hub()
    robot: Any = StandIn()
    return ConsolePilot(hub, robot, geometry("diffdrive-tb6612", None)), hub


def show(p: ConsolePilot, image: NDArray[np.uint8], i: int) -> Any:
    t = i / FPS
    track = p.on_frame(CameraFrame(image, t, i), Pose(0.0, 0.0, 0.0, time_s=t))
    p.command(Pose(0.0, 0.0, 0.0, time_s=t))  # takes the page's requests
    return track


def moving_patch(n: int) -> list[tuple[NDArray[np.uint8], tuple[int, int, int, int]]]:
    """A textured patch (a crop of one photo) sliding right over another photo: (frame, its box)."""
    scene = cv2.resize(photo("coffee"), (320, 240), interpolation=cv2.INTER_AREA)
    patch = cv2.resize(photo("chelsea")[60:260, 140:300], (48, 60), interpolation=cv2.INTER_AREA)
    frames = []
    for i in range(n):
        image, x = scene.copy(), 30 + 9 * i
        image[90:150, x : x + 48] = patch
        frames.append((np.ascontiguousarray(image), (x, 90, 48, 60)))
    return frames


def test_a_box_drawn_on_an_older_frame_starts_the_tracker_on_that_frame() -> None:
    """The page's frame is behind the robot's by the time the box arrives: the box names its frame."""
    p, hub = pilot()
    frames = moving_patch(16)
    for i, (image, _) in enumerate(frames[:10]):
        show(p, image, i)
    drawn_on = 4  # the user drew on frame 4; six more came meanwhile
    frame = hub.frame(drawn_on + 1)  # the hub numbers frames from 1
    assert frame is not None and np.array_equal(frame.image, frames[drawn_on][0])
    hub.post(select=Select(frame, frames[drawn_on][1]))
    p.command(Pose(0.0, 0.0, 0.0, time_s=10 / FPS))
    assert p.has_target
    for i in range(10, 16):
        image, truth = frames[i]
        track = show(p, image, i)
        assert track.found and track.box is not None
        assert iou(track.box, truth) > 0.6, (i, track.box, truth)  # the patch where it is now


@needs_detectors
def test_a_person_clicked_among_two_is_the_one_followed() -> None:
    image = photo("pedestrians_f050")  # two people walking side by side
    p, hub = pilot()
    hub.post(target_kind="person")
    p.command(Pose(0.0, 0.0, 0.0, time_s=0.0))
    assert isinstance(p.follow.tracker, ClassTracker)
    show(p, image, 0)
    _, _, overlay, _ = hub.latest()
    detections = [(d[0], d[1], d[2], d[3]) for d in overlay["detections"]]
    assert len(detections) >= 2, overlay
    people = PERSONS["pedestrians_f050"]
    chosen_by_default = show(p, image, 1).box
    other = next(person for person in people if iou(person, chosen_by_default) < 0.3)
    clicked = max(detections, key=lambda d: iou(d, other))  # the user clicks the other one's box
    assert iou(clicked, other) > 0.4
    shown = hub.frame(hub.frame_id)
    assert shown is not None
    hub.post(select=Select(shown, clicked))
    p.command(Pose(0.0, 0.0, 0.0, time_s=2 / FPS))
    for i in range(2, 8):
        track = show(p, image, i)
        assert track.found and track.box is not None
        assert iou(track.box, other) > 0.4 and iou(track.box, chosen_by_default) < 0.3, (i, track.box)


def open_floor(p: ConsolePilot) -> ConsolePilot:
    """A revolution with no return at all: nothing for the obstacle guard to stop for."""
    angles = np.linspace(-np.pi, np.pi, 360, endpoint=False)
    nothing = np.full(360, np.nan)
    scan = LidarScan("rplidar-a1", 0, angles, nothing, np.zeros(360, dtype=np.int64), np.zeros(360), 0.15, 12.0)
    p.on_scan(scan, Pose(0.0, 0.0, 0.0, time_s=0.0))
    return p


def test_a_car_is_not_asked_to_turn_standing_still_nor_tighter_than_its_steering() -> None:
    hub = Hub()
    robot: Any = StandIn()
    robot.armed = True
    car = geometry("picar", None)
    p = open_floor(ConsolePilot(hub, robot, replace(car, min_turn_radius_m=0.5)))
    now = hub.clock()
    hub.post(drive=Drive(0.0, 1.2, now))  # A or left arrow alone
    assert p.command(Pose(0.0, 0.0, 0.0, time_s=0.0))[:2] == (0.0, 0.0)
    hub.post(drive=Drive(0.3, 1.2, now))  # W and A: the tightest circle it steers
    assert p.command(Pose(0.0, 0.0, 0.0, time_s=0.0))[:2] == pytest.approx((0.3, 0.6))
    hub.post(drive=Drive(-0.3, -0.2, now))  # S and a little right: backing with the wheels to the right
    assert p.command(Pose(0.0, 0.0, 0.0, time_s=0.0))[:2] == pytest.approx((-0.3, 0.2))  # the nose swings left
    diff = open_floor(ConsolePilot(hub, robot, geometry("diffdrive-tb6612", None)))
    hub.post(drive=Drive(0.0, 1.2, now))  # a differential drive spins in place
    assert diff.command(Pose(0.0, 0.0, 0.0, time_s=0.0))[:2] == (0.0, 1.2)


def test_stop_ends_following_too() -> None:
    p, hub = pilot()
    hub.alive()  # the driving page's keep-alive
    hub.post(follow=True)
    p.command(Pose(0.0, 0.0, 0.0, time_s=0.0))
    assert p.following
    hub.stop()
    p.command(Pose(0.0, 0.0, 0.0, time_s=0.0))
    assert not p.following
