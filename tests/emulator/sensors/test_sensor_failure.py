"""An emulated device that fails goes dead; the board and the clock it shares carry on. And an
empty world (no shapes at all) is a world every device works in."""

from __future__ import annotations

import numpy as np
import pytest

from emulator.sensors.lidar import LidarModel
from emulator.transport.serve_log import fault_line
from host_sdk import Robot
from host_sdk.sensors import CameraSource, Jy901, Lidar

EMPTY = "emu://diffdrive-bts7960?seed=1&world=empty&imu=jy901&clock=virtual"


@pytest.mark.parametrize(("model", "camera"), [("rplidar-a1", "&camera=1"), ("ydlidar-f4", "")])
def test_an_empty_world_runs_a_minute_with_every_device(model: str, camera: str) -> None:
    # The camera renders every frame: once is enough (the empty world is the same for it).
    with Robot.connect(f"{EMPTY}&lidar={model}{camera}") as robot:
        emu = robot.transport.device
        lidar = Lidar.open(robot.transport.endpoints["lidar"], model)
        imu = Jy901.open(robot.transport.endpoints["imu"])
        cam = CameraSource(robot.transport.endpoints["camera"]) if camera else None
        lidar.start()
        scans, samples, frames = [], 0, 0
        while emu.now_us < 60_000_000:  # virtual time: the lidar's poll runs the emulator
            scans += lidar.poll(0.5)
            samples += len(imu.poll())
            frames += len(cam.poll()) if cam else 0
        assert emu.sensors.failed == {} and not [r for r in emu.faults if r.kind == "sensor_fail"]
        assert len(scans) > 60 * lidar.spec.scan_hz * 0.9
        assert samples > 60 * 100 and (frames > 60 * 10 or cam is None)
        # Nothing to see: every sample of every revolution is a no-return.
        assert all(len(s) > 100 and np.isnan(s.ranges_m).all() for s in scans)
        truth = emu.sensors.devices["lidar"].last_samples
        assert truth is not None and np.isinf(truth.true_range_m).all()
        for device in (lidar, imu, cam):
            if device is not None:
                device.close()


def test_a_device_that_raises_goes_dead_and_the_board_drives_on(monkeypatch: pytest.MonkeyPatch) -> None:
    url = "emu://diffdrive-bts7960?seed=1&world=random:1&lidar=rplidar-a1&imu=jy901&clock=virtual"
    with Robot.connect(url) as robot:
        emu = robot.transport.device
        lidar = Lidar.open(robot.transport.endpoints["lidar"], "rplidar-a1")
        lidar.start()
        lidar.read_scan()

        def broken(*args: object, **kwargs: object) -> None:
            raise RuntimeError("ray cast blew up")

        monkeypatch.setattr(LidarModel, "sample", broken)
        robot.arm()
        for _ in range(40):  # 2 s of driving, through many sensor ticks
            robot.drive(0.2, 0.0)
            robot.wait_feedback()
        assert robot.wait_feedback().wheel_speeds_m_s[0] > 0.1
        assert emu.sensors.failed == {"lidar": "RuntimeError: ray cast blew up"}
        records = [r for r in emu.faults if r.kind == "sensor_fail"]
        assert len(records) == 1, "logged once, when it failed"
        line = fault_line(records[0])
        assert line is not None and "lidar" in line and "RuntimeError: ray cast blew up" in line
        # Dead, as a real device would be: nothing more arrives (the IMU still talks).
        lidar.poll(0.3)
        before = lidar.counters.bytes_received
        lidar.poll(0.5)
        assert lidar.counters.bytes_received == before
        imu = Jy901.open(robot.transport.endpoints["imu"])
        assert imu.read() is not None
        imu.close()
        lidar.close()
