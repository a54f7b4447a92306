"""IMU + wheel odometry fusion on the emulator: heading error after a drive with turns on a
slippery floor, the EKF (host_sdk.fusion) against wheel odometry alone, in one run.

    python benchmarks/fusion.py              # 2-minute drives, both profiles, with and without compass
    python benchmarks/fusion.py --seconds 60 --profile picar

Each drive: the emulated robot with a JY901 at 200 Hz (gyro bias drawn per seed, random-walking)
and the tyres' friction lowered to `--traction` (0.15: the driven wheels slip when they accelerate
and turn), repeating 4 s straight, 4 s turning left, 4 s standing, 4 s turning right, then standing
for 2 s so the figures are read with the robot at rest (no lag between truth and estimate). Wheel
odometry is the SDK's (`robot.odometry`); the EKF gets each FEEDBACK's odometry increment, every
gyro sample and, in the compass rows, the magnetometer's heading (uncalibrated: a few degrees of
hard-iron error). Error = estimate - the plant's true heading, in the odometry frame.
"""

from __future__ import annotations

import argparse
import math
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass

from host_sdk import FeedbackSample, Robot
from host_sdk.fusion import OdometryIncrements, PoseEkf, compass_heading
from host_sdk.sensors import Jy901

PATTERN = ((0.4, 0.0), (0.3, 2.0), (0.0, 0.0), (0.3, -1.5))
"""(speed m/s, turn rate rad/s) for 4 s each; the PiCar steers 0.5 rad the same way."""


@dataclass(frozen=True)
class FusionRun:
    profile: str
    seconds: float
    compass: bool
    odometry_error_deg: float
    ekf_error_deg: float
    ekf_sigma_deg: float
    slip_steps: int
    wall_s: float

    @property
    def ratio(self) -> float:
        return abs(self.odometry_error_deg) / max(abs(self.ekf_error_deg), 1e-9)


def drive(profile: str, seconds: float, *, traction: float = 0.15, seed: int = 1, compass: bool = False) -> FusionRun:
    url = f"emu://{profile}?clock=virtual&seed={seed}&faults=traction%3D{traction}&world=random:{seed}&imu=jy901"
    wall = time.perf_counter()
    with Robot.connect(url) as robot:
        emu = robot.emulator
        emu.world = None  # an open floor: the drive is about heading, not about the room's walls
        imu = Jy901.open(robot.transport.endpoints["imu"])
        ekf = PoseEkf(time_s=robot.now())
        steps = OdometryIncrements()

        odometry: deque[tuple[float, float, float]] = deque()

        def on_feedback(sample: FeedbackSample) -> None:  # on the I/O thread: fused below, after the gyro
            if sample.pose is not None:
                ds, turn = steps.step(sample.pose.x_m, sample.pose.y_m, sample.pose.theta_rad)
                odometry.append((sample.host_time_s, ds, turn))

        robot.on_feedback(on_feedback)
        robot.arm()
        t0 = robot.now()
        while (t := robot.now() - t0) < seconds + 2.0:
            speed, rate = PATTERN[int(t / 4) % 4] if t < seconds else (0.0, 0.0)
            if profile == "picar":
                robot.drive_ackermann(speed, math.copysign(0.5, rate) if rate else 0.0, clamp=True)
            else:
                robot.drive(speed, rate, clamp=True)
            robot.sleep(0.02)
            for sample in imu.poll():
                if sample.gyro is not None:
                    ekf.add_gyro(sample.t, sample.gyro[2])
                if compass and sample.mag is not None:
                    ekf.add_heading(sample.t, compass_heading(sample.mag))
            while odometry:
                ekf.add_odometry(*odometry.popleft())
        truth = emu.truth.plant.theta_rad
        odo = math.degrees(math.remainder(robot.odometry.pose.theta_rad - truth, 2 * math.pi))
        fused = ekf.pose
        est = math.degrees(math.remainder(fused.theta_rad - truth, 2 * math.pi))
        imu.close()
    return FusionRun(profile, seconds, compass, odo, est, math.degrees(fused.heading_sigma_rad), ekf.slips,
                     time.perf_counter() - wall)  # fmt: skip


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seconds", type=float, default=120.0, help="length of the drive (default 120)")
    ap.add_argument("--profile", action="append", help="diffdrive-tb6612 and/or picar (default both)")
    ap.add_argument("--traction", type=float, default=0.15)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    profiles = args.profile or ["diffdrive-tb6612", "picar"]
    print(f"{args.seconds:g} s drive with turns, traction {args.traction:g}, seed {args.seed}\n")
    head = ("profile", "compass", "odometry", "EKF", "EKF 1-sigma", "ratio", "slip steps")
    print("{:18s} {:8s} {:>10s} {:>8s} {:>12s} {:>7s} {:>11s}".format(*head))
    for profile in profiles:
        for compass in (False, True):
            r = drive(profile, args.seconds, traction=args.traction, seed=args.seed, compass=compass)
            print(f"{profile:18s} {'yes' if compass else 'no':8s} {r.odometry_error_deg:9.1f}° {r.ekf_error_deg:7.2f}° "
                  f"{r.ekf_sigma_deg:11.2f}° {r.ratio:6.0f}x {r.slip_steps:11d}")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
