"""Sensor benchmarks: lidar parsing against the devices' point rates, camera rendering, and the
emulator with every sensor running on its virtual clock.

    python benchmarks/sensors.py            # about 30 s
    python benchmarks/sensors.py --quick    # a smoke run (a few seconds)

What is measured (best of `--repeat`, garbage collector paused, one process). Rates are per second
of this process's CPU time (`time.process_time`), so other jobs on a shared machine do not skew
them; the wall-clock rates of the same runs are printed beside them.

* **lidar parse**: 2 s of a device's byte stream (recorded from the emulated RPLIDAR A1 and YDLIDAR
  F4, so the bytes are the real wire format) fed to the SDK's parser in 4 KiB reads, as from a
  serial port; points per second of CPU, as a ratio to the device's point rate (the A1's 8,000
  samples/s in its fastest mode, the F4's 4,000).
* **camera render**: frames per second of the emulated Pi Camera v2 at 320x240 and 640x480, in each look, in the
  random:0 room, render plus JPEG encode (what a served frame costs), against the camera's 30 fps.
* **emulator**: virtual seconds per wall second of the PiCar emulator with an RPLIDAR A1 at 10 Hz,
  the camera at 30 fps (320x240, rendered and encoded) and the JY901 at 200 Hz, against the same
  emulator without sensors in the same run. The budget (docs/budgets.md) is >= 3x real time.
"""

from __future__ import annotations

import argparse
import gc
import time
from collections.abc import Callable

import cv2

from emulator import Emulator
from emulator.sensors import attach
from emulator.sensors.camera import LOOKS, CameraOptions
from host_sdk.sensors import rplidar, ydlidar
from protocol.sensors import DEVICES

DEVICE_RATE = {"rplidar-a1": 8000.0, "ydlidar-f4": 4000.0}


def best(fn: Callable[[], tuple[float, float, float]], repeat: int) -> tuple[float, float]:
    """(per CPU second, per wall second) of the best of `repeat` runs; fn() returns (work done, CPU
    seconds, wall seconds), timed with the garbage collector paused."""
    cpu_rate = wall_rate = 0.0
    for _ in range(repeat):
        gc.collect()
        gc.disable()
        try:
            work, cpu, wall = fn()
        finally:
            gc.enable()
        cpu_rate, wall_rate = max(cpu_rate, work / cpu), max(wall_rate, work / wall)
    return cpu_rate, wall_rate


class Stopwatch:
    def __init__(self) -> None:
        self.cpu0, self.wall0 = time.process_time(), time.perf_counter()

    def stop(self) -> tuple[float, float]:
        return time.process_time() - self.cpu0, time.perf_counter() - self.wall0


def record(model: str, seconds: float) -> bytes:
    emu = Emulator("diffdrive-bts7960", seed=1)
    rig = attach(emu, "random:1", lidar=model)
    dev = rig.devices["lidar"]
    dev.host_write(b"\xa5\x20" if model == "rplidar-a1" else b"\xa5\x60", emu.now_us)
    emu.advance(seconds)
    return bytes(dev.host_read(emu.now_us))


def lidar_parse(model: str, seconds: float, repeat: int) -> tuple[float, float, int]:
    data = record(model, seconds)
    chunks = [data[i : i + 4096] for i in range(0, len(data), 4096)]
    points = 0

    def run() -> tuple[float, float, float]:
        nonlocal points
        parser = rplidar.RPLidarParser() if model == "rplidar-a1" else ydlidar.YDLidarParser()
        watch = Stopwatch()
        for _ in range(10):
            parser.reset()
            parser.expect_scan()
            for chunk in chunks:
                parser.receive_data(chunk, 0.0)
                parser.events()
        cpu, wall = watch.stop()
        points = parser.counters.points // 10
        return float(parser.counters.points), cpu, wall

    cpu_rate, wall_rate = best(run, repeat)
    assert points > 0
    return cpu_rate, wall_rate, points


def camera_fps(width: int, height: int, frames: int, repeat: int, look: str = "plain") -> tuple[float, float]:
    emu = Emulator("picar", seed=0)
    rig = attach(emu, "random:0", camera=CameraOptions(width=width, height=height, look=look))
    cam = rig.devices["camera"]
    scene = rig.world.scene
    x, y, th = scene.start

    def run() -> tuple[float, float, float]:
        watch = Stopwatch()
        for i in range(frames):
            image = cam.renderer.render(scene, (x, y, th + 0.01 * i), 0.3, cam.rng, time_s=i / 30)
            cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, 85])
        return (frames, *watch.stop())

    return best(run, repeat)


def emulator_speed(seconds: float, repeat: int, *, sensors: bool) -> tuple[float, float]:
    def run() -> tuple[float, float, float]:
        emu = Emulator("picar", seed=0)
        if sensors:
            rig = attach(emu, "random:0", lidar="rplidar-a1", imu="jy901", camera=True, lidar_hz=10.0)
            rig.devices["camera"].always = True
            rig.devices["lidar"].host_write(b"\xa5\x20", emu.now_us)
        emu.advance(0.2)
        watch = Stopwatch()
        emu.advance(seconds)
        cpu, wall = watch.stop()
        if sensors:
            assert rig.devices["camera"].frames_rendered >= 29 * seconds
        return seconds, cpu, wall

    return best(run, repeat)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="a short smoke run")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    seconds = 0.5 if args.quick else 2.0
    frames = 10 if args.quick else 60
    repeat = 1 if args.quick else args.repeat

    print("lidar parse (4 KiB reads)                 per CPU second             (per wall second)")
    for model, device_rate in DEVICE_RATE.items():
        rate, wall, points = lidar_parse(model, seconds, repeat)
        print(
            f"  {model:11s} {rate:12,.0f} points/s = {rate / device_rate:6.1f}x the device's "
            f"{device_rate:,.0f}/s  ({wall:,.0f}/s; {points} points a pass)"
        )
    fps_device = DEVICES["pi-camera-v2"].fps  # type: ignore[union-attr]
    print("camera render + JPEG encode (random:0 room)")
    for look in LOOKS:
        for w, h in ((320, 240), (640, 480)):
            fps, wall = camera_fps(w, h, frames, repeat, look)
            print(
                f"  {look:5s} {w}x{h}   {fps:8.1f} fps = {fps / fps_device:5.1f}x the camera's {fps_device:g} fps "
                f"({wall:.1f} fps; {1000 / fps:.1f} ms a frame)"
            )
    bare, bare_wall = emulator_speed(seconds, repeat, sensors=False)
    full, full_wall = emulator_speed(seconds, repeat, sensors=True)
    print("emulator on the virtual clock (picar), virtual seconds per CPU second (per wall second)")
    print(f"  without sensors                                  {bare:6.1f}x real time ({bare_wall:.1f}x)")
    print(f"  lidar 10 Hz + camera 30 fps 320x240 + IMU 200 Hz {full:6.1f}x real time ({full_wall:.1f}x; budget >= 3x)")


if __name__ == "__main__":
    main()
