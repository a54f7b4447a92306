"""IMU + wheel odometry fusion on the emulator: the EKF (host_sdk.fusion) against wheel odometry
alone and against its own covariance, in three plants, with and without the compass.

    python benchmarks/fusion.py                        # both profiles, three plants, seeds 11..20 (long)
    python benchmarks/fusion.py --profile diffdrive-tb6612 --plant ideal --seeds 2 --seconds 60
    python benchmarks/fusion.py --jobs 2 --json fusion.json

Each drive: the emulated robot with a JY901 at 200 Hz (gyro bias drawn per seed, random-walking;
an uncalibrated magnetometer: a few degrees of hard-iron error that depends on the heading),
repeating 4 s straight, 4 s turning left, 4 s standing, 4 s turning right, then standing for 2 s.
Plants:

- ideal: nothing is wrong with the wheels: tyres that never slip (friction infinite), the robot
  built as configured;
- turn-error: turns read 4 % off: the track 4 % wider than configured (diff drive: every turn reads
  long), the steering linkage 4 % stronger (PiCar: the wheels turn further than the servo says);
- slippery: tyre friction 0.15: the driven wheels slip when they accelerate and turn.

Wheel odometry is the SDK's (`robot.odometry`); two EKFs, made for the robot as the SDK's PoseSource
makes its own (`params_for(robot.kinematics)`), get the same drive: each FEEDBACK's odometry
increment and every gyro sample, and one of them also every magnetometer heading. Errors are read
against the emulator's truth with the robot at rest (no lag between truth and estimate): at the
end of each standing phase, the first at 12 s, and at the end. Heading error = estimate - truth
in the odometry frame; position error = the distance between them.

Goals (the fused pose no worse than its best input, and its covariance honest):

- ideal: at every reading of the first 90 s (and the one at 92 s) the EKF's heading error is at
  most 1.5x the wheels' (or 0.5 degrees, whichever is larger) and its position error at most 1.5x
  the wheels' (or 1 cm);
- turn-error: at 60 s and 120 s the EKF's heading and position errors are at most a third of the wheels';
- every plant, with and without the compass: at 60 s and 120 s the EKF's heading error is within 3x
  its reported sigma, and its position error within 3 sigma (Mahalanobis distance of x, y <= 3).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from collections import deque
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass

import numpy as np

from host_sdk import FeedbackSample, Robot
from host_sdk.fusion import OdometryIncrements, PoseEkf, compass_heading, params_for
from host_sdk.sensors import Jy901

PATTERN = ((0.4, 0.0), (0.3, 2.0), (0.0, 0.0), (0.3, -1.5))
"""(speed m/s, turn rate rad/s) for 4 s each; the PiCar steers 0.5 rad the same way."""
PROFILES = ("diffdrive-tb6612", "picar")
PLANTS = ("ideal", "turn-error", "slippery")
SEEDS = range(11, 21)
"""Reported on (docs/autonomy.md); the tests drive other seeds (tests/host_sdk/autonomy/test_fusion_emulator.py)."""
REST_S = 2.0
IDEAL_WITHIN_S = 90.0
AT_S = (60.0, 120.0)


def url(profile: str, plant: str, seed: int) -> str:
    base = f"emu://{profile}?clock=virtual&seed={seed}&world=random:{seed}&imu=jy901"
    if plant == "slippery":
        return base + "&faults=traction%3D0.15"
    if plant == "turn-error":
        scale = "steering_ratio=1.04" if profile == "picar" else "track_scale=1.04"
        return base + "&faults=traction%3Dinf&" + scale
    return base + "&faults=traction%3Dinf"


@dataclass(frozen=True)
class Estimate:
    heading_deg: float
    """Error, estimate - truth."""
    position_m: float
    heading_sigma_deg: float = 0.0
    position_sigmas: float = 0.0
    """Mahalanobis distance of the (x, y) error under the EKF's covariance (0 for the wheels)."""


@dataclass(frozen=True)
class Reading:
    time_s: float
    wheels: Estimate
    ekf: Estimate
    ekf_compass: Estimate


@dataclass(frozen=True)
class Drive:
    profile: str
    plant: str
    seed: int
    seconds: float
    readings: tuple[Reading, ...]
    slip_steps: int
    wall_s: float

    def at(self, t: float) -> Reading:
        """The reading nearest `t` (60 s: the end of a standing phase; the drive's length: its end)."""
        return min(self.readings, key=lambda r: abs(r.time_s - t))


def reading_times(seconds: float) -> list[float]:
    """The end of each standing phase within the drive (the robot has stood 4 s), and the end."""
    ends = [16.0 * n + 12.0 for n in range(int(seconds // 16) + 1) if 16.0 * n + 12.0 <= seconds]
    return [*ends, seconds + REST_S]


def _error(
    robot_xyt: tuple[float, float, float], truth: tuple[float, float, float], cov: np.ndarray | None
) -> Estimate:
    dx, dy = robot_xyt[0] - truth[0], robot_xyt[1] - truth[1]
    heading = math.degrees(math.remainder(robot_xyt[2] - truth[2], 2 * math.pi))
    if cov is None:
        return Estimate(heading, math.hypot(dx, dy))
    e = np.array([dx, dy])
    sigmas = math.sqrt(float(e @ np.linalg.solve(cov[:2, :2], e)))
    return Estimate(heading, math.hypot(dx, dy), math.degrees(math.sqrt(float(cov[2, 2]))), sigmas)


def drive(profile: str, plant: str, seed: int, seconds: float = 120.0) -> Drive:
    wall = time.perf_counter()
    readings = []
    with Robot.connect(url(profile, plant, seed)) as robot:
        emu = robot.emulator
        emu.world = None  # an open floor: the drive is about the pose, not about the room's walls
        imu = Jy901.open(robot.transport.endpoints["imu"])
        params = params_for(robot.kinematics)  # as PoseSource and the ROS 2 node make theirs
        ekfs = (PoseEkf(params, time_s=robot.now()), PoseEkf(params, time_s=robot.now()))  # without, with the compass
        steps = OdometryIncrements()
        odometry: deque[tuple[float, float, float]] = deque()

        def on_feedback(sample: FeedbackSample) -> None:  # on the I/O thread: fused below, after the gyro
            if sample.pose is not None:
                ds, turn = steps.step(sample.pose.x_m, sample.pose.y_m, sample.pose.theta_rad)
                odometry.append((sample.host_time_s, ds, turn))

        robot.on_feedback(on_feedback)
        robot.arm()
        start = emu.truth.plant
        # Truth in the odometry frame: the odometry and the EKFs start at (0, 0, 0) where the plant stands.
        x0, y0, th0 = start.x_m, start.y_m, start.theta_rad
        t0 = robot.now()
        pending = reading_times(seconds)
        while pending:
            t = robot.now() - t0
            if t >= pending[0]:
                pending.pop(0)
                plant_now = emu.truth.plant
                c, s = math.cos(-th0), math.sin(-th0)
                px, py = plant_now.x_m - x0, plant_now.y_m - y0
                truth = (c * px - s * py, s * px + c * py, plant_now.theta_rad - th0)
                o = robot.odometry.pose
                fused = [e.pose for e in ekfs]
                readings.append(
                    Reading(
                        round(t, 2),
                        _error((o.x_m, o.y_m, o.theta_rad), truth, None),
                        *(_error((f.x_m, f.y_m, f.theta_rad), truth, f.covariance) for f in fused),
                    )
                )
                continue
            speed, rate = PATTERN[int(t / 4) % 4] if t < seconds else (0.0, 0.0)
            if profile == "picar":
                robot.drive_ackermann(speed, math.copysign(0.5, rate) if rate else 0.0, clamp=True)
            else:
                robot.drive(speed, rate, clamp=True)
            robot.sleep(0.02)
            for sample in imu.poll():
                if sample.gyro is not None:
                    for ekf in ekfs:
                        ekf.add_gyro(sample.t, sample.gyro[2])
                if sample.mag is not None:
                    ekfs[1].add_heading(sample.t, compass_heading(sample.mag))
            while odometry:
                step = odometry.popleft()
                for ekf in ekfs:
                    ekf.add_odometry(*step)
        imu.close()
    return Drive(profile, plant, seed, seconds, tuple(readings), ekfs[0].slips, time.perf_counter() - wall)


# -- the figures ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Row:
    profile: str
    plant: str
    compass: bool
    at_s: float
    seeds: int
    wheels_deg: float
    """Median |heading error| over the seeds."""
    ekf_deg: float
    sigma_deg: float
    """Median reported 1-sigma."""
    wheels_cm: float
    ekf_cm: float
    heading_covered: int
    """Seeds with |heading error| <= 3 sigma."""
    position_covered: int
    """Seeds with the position error within 3 sigma."""
    worst_sigmas: float
    """Largest |heading error| / sigma."""
    better: int
    """Seeds in which the EKF's heading and position errors are both at most a third of the wheels'."""
    within: int | None
    """Ideal plant: seeds in which the EKF stayed within its bound at every reading up to 90 s."""


def _within_bound(drive: Drive, compass: bool) -> bool:
    for r in drive.readings:
        if r.time_s > IDEAL_WITHIN_S + REST_S:
            break
        e = r.ekf_compass if compass else r.ekf
        if abs(e.heading_deg) > max(1.5 * abs(r.wheels.heading_deg), 0.5):
            return False
        if e.position_m > max(1.5 * r.wheels.position_m, 0.01):
            return False
    return True


def rows(drives: Sequence[Drive], seconds: float) -> list[Row]:
    out = []
    groups: dict[tuple[str, str], list[Drive]] = {}
    for d in drives:
        groups.setdefault((d.profile, d.plant), []).append(d)
    for (profile, plant), group in groups.items():
        for compass in (False, True):
            for at in [a for a in AT_S if a <= seconds] or [seconds]:
                picked = [d.at(at if at < seconds else seconds + REST_S) for d in group]
                ekf = [r.ekf_compass if compass else r.ekf for r in picked]
                sig = [abs(e.heading_deg) / max(e.heading_sigma_deg, 1e-12) for e in ekf]
                better = sum(
                    abs(e.heading_deg) * 3 <= abs(r.wheels.heading_deg) and e.position_m * 3 <= r.wheels.position_m
                    for e, r in zip(ekf, picked, strict=True)
                )
                out.append(
                    Row(
                        profile,
                        plant,
                        compass,
                        at,
                        len(group),
                        float(np.median([abs(r.wheels.heading_deg) for r in picked])),
                        float(np.median([abs(e.heading_deg) for e in ekf])),
                        float(np.median([e.heading_sigma_deg for e in ekf])),
                        float(np.median([100 * r.wheels.position_m for r in picked])),
                        float(np.median([100 * e.position_m for e in ekf])),
                        sum(s <= 3 for s in sig),
                        sum(e.position_sigmas <= 3 for e in ekf),
                        max(sig),
                        better,
                        sum(_within_bound(d, compass) for d in group) if plant == "ideal" else None,
                    )
                )
    return out


def worst_readings(drives: Sequence[Drive]) -> list[tuple[str, str, bool, float, float, float]]:
    """Per profile, plant and compass, over every reading of every seed: the largest heading error in
    sigmas, and the largest position error in sigmas with its time (the goals look at 60 and 120 s)."""
    out = []
    keys = sorted({(d.profile, d.plant) for d in drives}, key=lambda k: (k[0], PLANTS.index(k[1])))
    for profile, plant in keys:
        for compass in (False, True):
            readings = [r for d in drives if (d.profile, d.plant) == (profile, plant) for r in d.readings]
            ekf = [(r.time_s, r.ekf_compass if compass else r.ekf) for r in readings]
            heading = max(abs(e.heading_deg) / max(e.heading_sigma_deg, 1e-12) for _, e in ekf)
            t, e = max(ekf, key=lambda te: te[1].position_sigmas)
            out.append((profile, plant, compass, heading, e.position_sigmas, t))
    return out


def goals(table: Sequence[Row]) -> list[tuple[str, bool]]:
    out = []
    for r in table:
        name = f"{r.profile} {r.plant} {'compass' if r.compass else 'gyro'} {r.at_s:g} s"
        out.append((f"{name}: heading within 3 sigma in {r.heading_covered}/{r.seeds}", r.heading_covered == r.seeds))
        out.append(
            (f"{name}: position within 3 sigma in {r.position_covered}/{r.seeds}", r.position_covered == r.seeds)
        )
        if r.plant == "turn-error":
            out.append((f"{name}: 3x better than the wheels in {r.better}/{r.seeds}", r.better == r.seeds))
        if r.within is not None and r.at_s == AT_S[0]:
            what = f"within max(1.5x the wheels, 0.5 deg / 1 cm) up to {IDEAL_WITHIN_S:g} s"
            out.append(
                (
                    f"{r.profile} ideal {'compass' if r.compass else 'gyro'}: {what} in {r.within}/{r.seeds}",
                    r.within == r.seeds,
                )
            )
    return out


def print_table(table: Sequence[Row]) -> None:
    head = ("profile", "plant", "compass", "at", "wheels", "EKF", "1-sigma", "wheels", "EKF", "3-sigma", "worst", "3x")
    print("{:17s} {:10s} {:7s} {:>5s} {:>8s} {:>7s} {:>7s} {:>8s} {:>7s} {:>11s} {:>6s} {:>5s}".format(*head))
    print(
        "{:17s} {:10s} {:7s} {:>5s} {:>8s} {:>7s} {:>7s} {:>8s} {:>7s} {:>11s} {:>6s} {:>5s}".format(
            "", "", "", "s", "deg", "deg", "deg", "cm", "cm", "hdg/pos", "sigma", ""
        )
    )
    for r in table:
        cover = f"{r.heading_covered}/{r.seeds} {r.position_covered}/{r.seeds}"
        print(
            f"{r.profile:17s} {r.plant:10s} {'yes' if r.compass else 'no':7s} {r.at_s:5.0f} {r.wheels_deg:8.2f} "
            f"{r.ekf_deg:7.2f} {r.sigma_deg:7.2f} {r.wheels_cm:8.1f} {r.ekf_cm:7.1f} {cover:>11s} "
            f"{r.worst_sigmas:6.1f} {r.better:2d}/{r.seeds}"
        )


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seconds", type=float, default=120.0, help="length of each drive (default 120)")
    ap.add_argument("--profile", action="append", choices=PROFILES, help="default: both")
    ap.add_argument("--plant", action="append", choices=PLANTS, help="default: all three")
    ap.add_argument("--first-seed", type=int, default=SEEDS.start, help=f"default {SEEDS.start}")
    ap.add_argument("--seeds", type=int, default=len(SEEDS), help=f"how many (default {len(SEEDS)})")
    ap.add_argument("--jobs", type=int, default=1, help="drives run side by side (processes)")
    ap.add_argument("--json", metavar="PATH", help="also write every reading as JSON")
    args = ap.parse_args(argv)
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    cases = [(p, plant, s) for p in args.profile or PROFILES for plant in args.plant or PLANTS for s in seeds]
    print(
        f"{args.seconds:g} s drives with turns and stops, seeds {seeds.start}..{seeds.stop - 1}, {len(cases)} drives\n",
        flush=True,
    )
    wall = time.perf_counter()
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as pool:
            drives = list(pool.map(drive, *zip(*cases, strict=True), [args.seconds] * len(cases)))
    else:
        drives = [drive(*case, seconds=args.seconds) for case in cases]
    table = rows(drives, args.seconds)
    print_table(table)
    print()
    for profile, plant, compass, heading, position, at in worst_readings(drives):
        print(
            f"every reading, {profile} {plant} {'compass' if compass else 'gyro'}: worst heading error "
            f"{heading:.1f} sigma, worst position error {position:.1f} sigma (at {at:g} s)"
        )
    print()
    verdicts = goals(table)
    for text, ok in verdicts:
        print(f"{'ok  ' if ok else 'MISS'} {text}")
    print(f"\n{time.perf_counter() - wall:.0f} s wall")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"drives": [asdict(d) for d in drives], "rows": [asdict(r) for r in table]}, f, indent=1)
    return 0 if all(ok for _, ok in verdicts) else 1


if __name__ == "__main__":
    raise SystemExit(main())
