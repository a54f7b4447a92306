"""The sensor models' physics, through the devices' own bytes where it matters: dropouts, range
limits, a scan skewed by the robot's turn, and the IMU's configuration commands."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from emulator import Emulator
from emulator.rng import Streams
from emulator.sensors import attach
from emulator.sensors.lidar import LidarModel
from emulator.world import parse_scenario
from host_sdk.sensors import rplidar, wit
from protocol.sensors import DEVICES, LidarSpec, Mount


def _model(name: str = "rplidar-a1") -> LidarModel:
    spec = DEVICES[name]
    assert isinstance(spec, LidarSpec)
    rng = np.random.Generator(np.random.PCG64(Streams(1).get("t").getrandbits(64)))
    return LidarModel(spec, Mount(name, "lidar"), rng)


def _still(x: float, y: float, th: float):  # type: ignore[no-untyped-def]
    def pose_at(times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        one = np.ones(times.shape)
        return x * one, y * one, th * one

    return pose_at


def test_no_return_beyond_range_and_on_glancing_walls() -> None:
    # A long corridor, 0.6 m wide: beams along it see walls at glancing angles or nothing in range.
    scene = parse_scenario({"walls": [{"from": [-30, 0.3], "to": [30, 0.3]}, {"from": [-30, -0.3], "to": [30, -0.3]}]})
    model = _model()
    model.start(0)
    s = model.sample(scene, 400_000, _still(0.0, 0.0, 0.0))
    assert s is not None
    side = np.abs(np.sin(np.radians(s.angle_deg)))  # 1: straight at a wall, 0: along the corridor
    along = side < 0.01  # farther than 12 m or nearly parallel: never a return
    assert (s.range_m[along] == 0).all() and (s.quality[along] == 0).all()
    head_on = side > 0.9
    assert (s.range_m[head_on] > 0).mean() > 0.95
    glancing = (side > 0.05) & (side < 0.08)  # 85..87 degrees of incidence
    assert (s.range_m[glancing] > 0).mean() < 0.05
    valid = s.range_m > 0
    sigma = np.maximum(0.0005, 0.005 * s.true_range_m[valid])
    assert (np.abs(s.range_m[valid] - s.true_range_m[valid]) < 5 * sigma).all()


def test_a_scan_taken_while_turning_is_skewed_by_the_turn() -> None:
    # A post 1 m ahead in an empty world, the robot spinning at 2 rad/s: the rotor angle at which the
    # post is hit moves with the heading during the revolution, so the world bearing stays put.
    scene = parse_scenario({"cylinders": [{"center": [1.0, 0.0], "radius_m": 0.05}]})
    model = _model()
    model.start(0)
    turn = 2.0  # rad/s

    def turning(times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return np.zeros(times.shape), np.zeros(times.shape), turn * times / 1e6

    s = model.sample(scene, 400_000, turning)
    assert s is not None
    hit = (s.range_m > 0) & (s.range_m < 1.0)
    assert hit.any()
    # Where the post appears: the rotor angle (clockwise) at which it was hit plus the heading then.
    heading = turn * s.time_us[hit] / 1e6
    world_bearing = heading - np.radians(s.angle_deg[hit])
    assert np.allclose(np.angle(np.exp(1j * world_bearing)), 0.0, atol=0.06)


def test_rplidar_reset_banner_is_skipped_and_counted() -> None:
    emu = Emulator("diffdrive-bts7960", seed=1)
    rig = attach(emu, "random:1", lidar="rplidar-a1")
    dev = rig.devices["lidar"]
    dev.host_write(b"\xa5\x40", emu.now_us)
    emu.advance(0.05)
    dev.host_write(b"\xa5\x52", emu.now_us)
    emu.advance(0.05)
    parser = rplidar.RPLidarParser()
    parser.receive_data(dev.host_read(emu.now_us))
    assert parser.events() == [rplidar.DeviceHealth(0, 0)]
    assert parser.counters.bytes_discarded > 20  # the text banner


def test_jy901_configuration_commands_change_what_it_sends() -> None:
    emu = Emulator("diffdrive-tb6612", seed=1)
    rig = attach(emu, "random:1", imu="jy901")
    dev = rig.devices["imu"]
    parser = wit.WitParser()

    def listen(seconds: float) -> list[wit.ImuSample]:
        dev.host_read(emu.now_us)
        emu.advance(seconds)
        parser.receive_data(dev.host_read(emu.now_us))
        return [e for e in parser.events() if isinstance(e, wit.ImuSample)]

    assert len(listen(1.0)) == pytest.approx(200, abs=2)
    dev.host_write(wit.set_rate(50), emu.now_us)  # locked: ignored
    assert len(listen(1.0)) == pytest.approx(200, abs=2) and dev.writes_locked == 1
    dev.host_write(wit.unlock() + wit.set_rate(50) + wit.set_outputs("acc", "angle"), emu.now_us)
    samples = listen(1.0)[2:]
    assert len(samples) == pytest.approx(48, abs=2)
    assert all(s.accel is not None and s.angle is not None and s.gyro is None for s in samples)
    dev.host_write(wit.unlock() + wit.set_outputs("time", "acc", "gyro", "angle", "mag", "quat"), emu.now_us)
    dev.host_write(wit.set_rate(200), emu.now_us)
    listen(1.0)
    assert dev.packets_dropped > 0  # 66 bytes every 5 ms is more than 115200 baud carries
    dev.host_write(wit.unlock() + wit.calibrate("heading_zero"), emu.now_us)
    later = listen(0.2)
    assert later[-1].angle is not None and abs(later[-1].angle[2]) < math.radians(0.5)


def test_a_camera_behind_the_wall_clock_skips_stale_frames_and_numbers_them() -> None:
    """On the real clock, an emulator that fell behind (a stall at start, a busy machine) catches up
    without rendering frames already stale, or it would fall further behind; a reader sees them as
    dropped (the frame numbers jump). On the virtual clock every frame is rendered."""
    from emulator.sensors.camera import CameraOptions
    from emulator.sensors.mjpeg import STALE_FRAMES

    def camera(realtime_us: int | None) -> Any:
        emu = Emulator("picar", seed=1)
        rig = attach(emu, "random:1", camera=CameraOptions(fps=30.0))
        dev = rig.devices["camera"]
        dev.always = True
        if realtime_us is not None:
            emu.realtime_us = lambda: realtime_us
        emu.advance_to_us(2_000_000)
        return dev

    lagging = camera(2_000_000)  # the wall clock is at 2 s: every frame before 2 s - 2 periods is stale
    assert 1 <= lagging.frames_rendered <= STALE_FRAMES  # the last ones only
    assert lagging.seq == 60 and lagging.frames_skipped == 60 - lagging.frames_rendered
    assert len(lagging.truth) == lagging.frames_rendered
    virtual = camera(None)
    assert virtual.frames_rendered == virtual.seq == 60 and virtual.frames_skipped == 0


def test_the_lidar_reports_each_pass_of_its_rear_as_ground_truth() -> None:
    """`on_rear` (roverlink emulate --truth) gets the first sample at or past 180 deg of every
    revolution: the measurement time of a LaserScan's ray 0."""
    emu = Emulator("diffdrive-bts7960", seed=4)
    rig = attach(emu, "random:1", lidar="rplidar-a1")
    dev = rig.devices["lidar"]
    rears: list[int] = []
    times: list[np.ndarray[Any, Any]] = []
    angles: list[np.ndarray[Any, Any]] = []
    dev.on_rear = rears.append
    emit = dev.emit

    def recorded(samples: Any) -> None:
        times.append(samples.time_us)
        angles.append(samples.angle_deg)
        emit(samples)

    dev.emit = recorded
    dev.host_write(b"\xa5\x20", emu.now_us)  # SCAN
    emu.advance(2.0)
    t, a = np.concatenate(times), np.concatenate(angles)
    assert len(rears) == pytest.approx(2.0 * dev.spec.scan_hz, abs=1.5)
    for r in rears:
        i = int(np.searchsorted(t, r))
        assert t[i] == r and a[i] >= 180.0 and (i == 0 or a[i - 1] < 180.0), (r, a[i - 1 : i + 1])
    gaps = np.diff(rears) / 1e6
    assert np.all(np.abs(gaps * dev.spec.scan_hz - 1) < 0.02), gaps  # one a revolution, the rotor's 1 % wander
