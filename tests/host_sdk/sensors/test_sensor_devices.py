"""The SDK's drivers read the emulated devices in-process (emu:// + emudev://, virtual clock) and
agree with the ground truth; one seed gives the same bytes from every device."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from sensor_truth import agreement

from emulator import Emulator
from emulator.sensors import attach
from host_sdk.sensors import CameraSource, Jy901, Lidar
from host_sdk.transport import open_transport

ROOM = Path(__file__).resolve().parents[3] / "examples" / "worlds" / "room.toml"


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


@pytest.mark.parametrize(("profile", "model"), [("diffdrive-bts7960", "rplidar-a1"), ("picar", "ydlidar-f4")])
def test_scan_ranges_agree_with_the_scene(profile: str, model: str) -> None:
    transport = open_transport(f"emu://{profile}?clock=virtual&seed=2&world={ROOM}&lidar={model}", 115200)
    with Lidar.open(transport.endpoints["lidar"], model) as lidar:
        assert lidar.health().ok
        lidar.start()
        scans = [lidar.read_scan() for _ in range(3)]
    emu = transport.device
    rig = emu.sensors
    mount = rig.devices["lidar"].model.mount
    spec = rig.devices["lidar"].spec
    for scan in scans:
        assert len(scan) == pytest.approx(spec.sample_rate_hz / spec.scan_hz, rel=0.03)
        assert np.isfinite(scan.ranges_m).mean() > 0.9  # a closed room: few dropouts
        # The target moves: compare each revolution with the scene at its own time.
        rig.world.scene.set_time(scan.time_s + scan.duration_s / 2)
        assert agreement(scan, rig.world.scene, rig.world.scene.start, mount) > 0.97
        assert scan.times_s[-1] - scan.times_s[0] == pytest.approx(1 / spec.scan_hz, rel=0.05)
    assert lidar.counters.framing_errors == lidar.counters.checksum_errors == 0
    regular = scans[-1].regular(360)  # what a LaserScan message carries
    assert regular.ranges_m.shape == (360,) and regular.angle_increment == pytest.approx(math.pi / 180)
    assert np.isfinite(regular.ranges_m).mean() > 0.85
    assert regular.time_increment_s == pytest.approx(-1 / spec.scan_hz / 360, rel=0.05)  # clockwise devices
    last = scans[-1]
    bins = np.floor((last.angles_rad + math.pi) / regular.angle_increment).astype(int) % 360
    for b in np.flatnonzero(np.isfinite(regular.ranges_m))[::37]:  # each bin: its nearest return
        assert regular.ranges_m[b] == np.nanmin(np.where(bins == b, last.ranges_m, np.nan))
    transport.close()


def test_imu_yaw_follows_the_true_heading_within_its_bias_model() -> None:
    transport = open_transport(f"emu://diffdrive-tb6612?clock=virtual&seed=4&world={ROOM}&imu=jy901", 115200)
    emu = transport.device
    with Jy901.open(transport.endpoints["imu"]) as imu:
        sample = imu.read()
        heading = emu.truth.world.theta_rad
        assert sample.accel is not None and sample.accel[2] == pytest.approx(9.81, abs=0.3)
        assert sample.gyro is not None and abs(sample.gyro[2]) < math.radians(0.5)
        assert sample.angle is not None
        # An uncalibrated compass: a hard-iron heading error of a few degrees (5 % of the field).
        assert abs(_wrap(sample.angle[2] - heading)) < 0.2
        imu.calibrate("mag")
        imu.calibrate("normal")
        for _ in range(2000):  # 10 s at 200 Hz: the filter (2 s) settles on the corrected compass
            sample = imu.read()
        assert sample.angle is not None and abs(_wrap(sample.angle[2] - heading)) < math.radians(1.0)
        assert imu.counters.checksum_errors == 0 and emu.sensors.devices["imu"].packets_dropped == 0
        assert sample.t == pytest.approx(transport.clock(), abs=0.02)
    transport.close()


def test_camera_sees_the_target_ahead(tmp_path: Path) -> None:
    world = tmp_path / "target.toml"
    world.write_text(
        "[world]\nsize_m = [6.0, 4.0]\n[start]\nx_m = 1.0\ny_m = 2.0\n[target]\npath = [[2.5, 2.0]]\nradius_m = 0.15\n",
        encoding="utf-8",
    )
    transport = open_transport(f"emu://picar?clock=virtual&world={world}&camera=320x240", 115200)
    with CameraSource(transport.endpoints["camera"]) as cam:
        frames = [cam.read() for _ in range(3)]
    image = frames[-1].image
    assert image.shape == (240, 320, 3)
    b, g, r = (image[..., i].astype(int) for i in range(3))
    magenta = (b > 150) & (r > 150) & (g < 90)
    cols = np.flatnonzero(magenta.any(axis=0))
    assert magenta.sum() > 300
    assert abs((cols.min() + cols.max()) / 2 - 160) < 8  # straight ahead: centred
    truth = transport.device.sensors.devices["camera"].truth[3]  # the ground truth of that frame
    assert truth.target_bbox is not None and truth.target_distance_m == pytest.approx(2.5 - 1.0 - 0.30)
    x0, y0, x1, y1 = truth.target_bbox
    ys, xs = np.nonzero(magenta)
    assert x0 <= xs.min() and xs.max() < x1 and y0 <= ys.min() and ys.max() < y1
    assert [f.seq for f in frames] == [1, 2, 3] and cam.dropped == 0
    t0, t1 = frames[0].device_time_s, frames[1].device_time_s
    assert t0 is not None and t1 is not None and t1 - t0 == pytest.approx(1 / 30, abs=1e-5)
    # Taken off the pipe within one sensor batch (5 ms) of the exposure.
    assert all(0 <= f.time_s - (f.device_time_s or 0) <= 0.0051 for f in frames)
    transport.close()


def _device_bytes(seed: int) -> dict[str, bytes]:
    emu = Emulator("picar", seed=seed)
    rig = attach(emu, f"random:{seed}", lidar="rplidar-a1", imu="jy901", camera=True)
    frames: list[bytes] = []
    rig.devices["camera"].listeners.append(lambda f: frames.append(f.jpeg))
    rig.devices["lidar"].host_write(b"\xa5\x20", emu.now_us)
    emu.advance(0.5)
    return {
        "lidar": rig.devices["lidar"].host_read(emu.now_us),
        "imu": rig.devices["imu"].host_read(emu.now_us),
        "camera": b"".join(frames),
    }


def test_the_same_seed_gives_the_same_bytes_from_every_device() -> None:
    a, b, c = _device_bytes(7), _device_bytes(7), _device_bytes(8)
    for kind in ("lidar", "imu", "camera"):
        assert len(a[kind]) > 1000
        assert a[kind] == b[kind], kind
        assert a[kind] != c[kind], kind


def test_any_device_goes_on_any_profile() -> None:
    emu = Emulator("picar", seed=1)  # the PiCar carries no IMU and a YDLIDAR, not an RPLIDAR
    rig = attach(emu, "random:1", lidar="rplidar-a1", imu="jy901")
    assert rig.devices["lidar"].model.mount.z_m > 0  # where the PiCar carries its lidar
    assert rig.devices["imu"].spec.name == "jy901"
    rig.devices["lidar"].host_write(b"\xa5\x20", emu.now_us)
    emu.advance(0.5)
    assert len(rig.devices["lidar"].host_read(emu.now_us)) > 3000
    assert len(rig.devices["imu"].host_read(emu.now_us)) > 5000


def test_bad_sensor_options_are_named() -> None:
    with pytest.raises(ValueError, match="lidar = 'sick-lms' is not allowed: rplidar-a1 or ydlidar-f4"):
        open_transport("emu://picar?clock=virtual&lidar=sick-lms", 115200)
    with pytest.raises(ValueError, match=r"lidar scan_hz = 20.0 is not allowed: 1\.\.10 Hz"):
        open_transport("emu://picar?clock=virtual&lidar=rplidar-a1&lidar_hz=20", 115200)
    with pytest.raises(ValueError, match="camera size = '100x100' is not allowed: 320x240 or 640x480"):
        open_transport("emu://picar?clock=virtual&camera=100x100", 115200)


def test_devices_on_the_wall_clock_in_process() -> None:
    transport = open_transport(f"emu://diffdrive-bts7960?clock=real&world={ROOM}&lidar=rplidar-a1", 115200)
    try:
        with Lidar.open(transport.endpoints["lidar"], "rplidar-a1") as lidar:
            lidar.start()
            scan = lidar.read_scan(timeout_s=3.0)
        assert len(scan) > 300
        # Stamped with the host's monotonic clock, as a real port is.
        assert abs(scan.times_s[-1] - transport.clock()) < 1.0
    finally:
        transport.close()


@pytest.mark.parametrize("model", ["rplidar-a1", "ydlidar-f4"])
def test_a_noisy_lidar_line_costs_points_not_scans(model: str) -> None:
    transport = open_transport(f"emu://picar?clock=virtual&seed=6&world={ROOM}&lidar={model}", 115200)
    line = transport.device.sensors.devices["lidar"].tx
    with Lidar.open(transport.endpoints["lidar"], model) as lidar:
        lidar.start()
        lidar.read_scan()
        line.bitflip = 2e-4  # about one flipped bit in 600 bytes
        scans = [lidar.read_scan() for _ in range(5)]
        c = lidar.counters
        assert line.stats.bits_flipped > 0
        assert c.framing_errors + c.checksum_errors + c.bytes_discarded > 0
        assert all(len(s) > 300 for s in scans)
    transport.close()
