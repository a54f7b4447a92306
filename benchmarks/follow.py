"""Follow-while-avoiding on the emulator, RoverLink against the PiCar team's approach.

RoverLink's behaviour against the PiCar team's published approach, on the same seeded random
worlds, per profile, in one run.

    python benchmarks/follow.py                       # 50 worlds x 2 profiles x 2 pilots, 40 s each
    python benchmarks/follow.py --worlds 10 --jobs 2  # fewer worlds, two processes
    python benchmarks/follow.py --json results.json   # also every run's metrics
    python benchmarks/follow.py --look photo          # the photographic camera (textures, light, look-alikes)

Each run: `roverlink follow`'s loop (roverlink.follow) on the emulator's virtual clock, seed = the
world's number, `random:SEED` (a walled room 4-7 x 3-5 m with 3-6 boxes and 2-4 cylinders, a target
moving at 0.15-0.3 m/s round 3-4 waypoints, the robot somewhere in it facing anywhere), the
profile's lidar (PiCar: YDLIDAR F4; diff-drive car: an RPLIDAR A1 on top), the Pi Camera v2 model at
`--fps` in the `--look` (plain: flat shapes; photo: textured walls and floor, shading, exposure
drift, look-alike distractors), the JY901 at 200 Hz; the same template and detector for both pilots, the same top speed.

Per profile and pilot: collisions (contacts recorded by the emulator: obstacles and the target,
and how many of them the robot was run into: it stood or moved away, and the target walked into it),
worlds with any; the target in the camera's view (truth: inside the field of view with a clear line
of sight) as a share of the time from the first sight; the mean and worst following error
(|gap - the wanted gap|: 0.9 m on the PiCar, 0.5 m on the diff-drive car; gap = footprint to target
surface, while in view); reacquisition times (target lost
by the tracker until found again); time to the first sight; the CPU time the pilot takes to decide a
control step (mean over the runs, and the median over the runs of each run's 99th percentile; the
pilot's share of a 50 ms control period). Virtual time: the wall time depends on the machine only.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from emulator.sensors.camera import LOOKS
from roverlink.follow.app import FollowSettings, run_emulated

PROFILES = ("picar", "diffdrive-tb6612")
PILOTS = ("roverlink", "picar-2018")


def one(job: tuple[str, str, int, float, float, str]) -> dict[str, Any]:
    profile, pilot, seed, duration, fps, look = job
    t0 = time.perf_counter()
    try:
        # rearm: a failsafe is counted and the run goes on, as it was always measured (an explicit opt-in)
        settings = FollowSettings(duration_s=duration, rearm=True)
        m = run_emulated(
            profile, f"random:{seed}", pilot=pilot, seed=seed, camera_fps=fps, settings=settings, camera_look=look
        )
        out = m.to_json()
    except Exception as exc:  # a run that breaks is reported, not allowed to end the benchmark
        out = {"pilot": pilot, "profile": profile, "world": f"random:{seed}", "error": repr(exc)}
    out["seed"] = seed
    out["look"] = look
    out["wall_s"] = round(time.perf_counter() - t0, 1)
    return out


def summarise(runs: list[dict[str, Any]]) -> dict[str, Any]:
    ok = [r for r in runs if "error" not in r]
    views = [r["in_view_fraction"] or 0.0 for r in ok if r["first_sight_s"] is not None]
    errors = [r["follow_error_mean_m"] for r in ok if r["follow_error_mean_m"] is not None]
    worst = [r["follow_error_max_m"] for r in ok if r["follow_error_max_m"] is not None]
    reacq = [v for r in ok for v in r["reacquisitions_s"]]
    sights = [r["first_sight_s"] for r in ok if r["first_sight_s"] is not None]
    decide = [r["decide_ms_mean"] for r in ok if r.get("decide_ms_mean") is not None]
    p99 = [r["decide_ms_p99"] for r in ok if r.get("decide_ms_p99") is not None]
    return {
        "runs": len(runs),
        "errors": len(runs) - len(ok),
        "collisions": sum(r["collisions"] for r in ok),
        "target_contacts": sum(1 for r in ok for hit in r["collided_with"] if hit == "target"),
        "worlds_with_collisions": sum(1 for r in ok if r["collisions"]),
        "run_into": sum(r.get("run_into", 0) for r in ok),
        "never_saw_target": sum(1 for r in ok if r["first_sight_s"] is None),
        "in_view_mean": statistics.fmean(views) if views else math.nan,
        "in_view_min": min(views) if views else math.nan,
        "worlds_in_view_90": sum(1 for v in views if v >= 0.9),
        "follow_error_mean_m": statistics.fmean(errors) if errors else math.nan,
        "follow_error_max_m": max(worst) if worst else math.nan,
        "reacquisitions": len(reacq),
        "reacquisition_mean_s": statistics.fmean(reacq) if reacq else math.nan,
        "reacquisition_max_s": max(reacq) if reacq else math.nan,
        "first_sight_mean_s": statistics.fmean(sights) if sights else math.nan,
        "failsafes": sum(r["failsafes"] for r in ok),
        "decide_ms_mean": statistics.fmean(decide) if decide else math.nan,
        "decide_ms_p99": statistics.median(p99) if p99 else math.nan,
    }


def table(summary: dict[str, dict[str, dict[str, Any]]], worlds: int, duration: float, look: str) -> str:
    rows = [
        f"{worlds} worlds (random:0..{worlds - 1}) per profile, {duration:g} s each, "
        f"camera look {look}, virtual clock\n",
        "| profile | pilot | collisions (worlds): obstacles + the target (of which run into) | saw the target "
        "| target in view, mean (min) "
        "| worlds >= 90 % in view | following error mean / worst | reacquisitions: count, mean / max "
        "| first sight, mean | deciding a step: mean / p99 |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for profile, pilots in summary.items():
        for pilot, s in pilots.items():
            rows.append(
                f"| {profile} | {pilot} | {s['collisions']} ({s['worlds_with_collisions']}): "
                f"{s['collisions'] - s['target_contacts']} + {s['target_contacts']} ({s['run_into']}) | "
                f"{s['runs'] - s['errors'] - s['never_saw_target']} of {s['runs']} | "
                f"{100 * s['in_view_mean']:.1f} % ({100 * s['in_view_min']:.1f} %) | {s['worlds_in_view_90']} | "
                f"{s['follow_error_mean_m']:.2f} / {s['follow_error_max_m']:.2f} m | "
                f"{s['reacquisitions']}, {s['reacquisition_mean_s']:.1f} / {s['reacquisition_max_s']:.1f} s | "
                f"{s['first_sight_mean_s']:.1f} s | {s['decide_ms_mean']:.1f} / {s['decide_ms_p99']:.1f} ms |"
            )
    return "\n".join(rows)


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--worlds", type=int, default=50, help="random:0 .. random:N-1 (default 50)")
    ap.add_argument("--first", type=int, default=0, help="first world's number (default 0)")
    ap.add_argument("--duration", type=float, default=40.0, help="seconds of virtual time per run (default 40)")
    ap.add_argument("--fps", type=float, default=15.0, help="camera frame rate (default 15)")
    ap.add_argument("--profile", action="append", choices=PROFILES, help="default: both")
    ap.add_argument("--pilot", action="append", choices=PILOTS, help="default: both")
    ap.add_argument("--look", choices=LOOKS, default="plain", help="the emulated camera's look (default plain)")
    ap.add_argument("--jobs", type=int, default=1, help="processes (default 1)")
    ap.add_argument("--json", type=Path, help="write every run's metrics and the summary here")
    ap.add_argument("--from-json", type=Path, metavar="FILE", help="summarise the runs saved in FILE (no new runs)")
    args = ap.parse_args(argv)
    if args.from_json:
        saved = json.loads(args.from_json.read_text())["runs"]
        worlds = len({r["seed"] for r in saved})
        duration = max((r.get("duration_s", 0.0) for r in saved), default=0.0)
        pairs = sorted({(r["profile"], r["pilot"]) for r in saved})
        pairs.sort(key=lambda k: (PROFILES.index(k[0]), PILOTS.index(k[1])))
        summary: dict[str, dict[str, dict[str, Any]]] = {}
        for pr, pi in pairs:
            summary.setdefault(pr, {})[pi] = summarise([r for r in saved if r["profile"] == pr and r["pilot"] == pi])
        looks = sorted({r.get("look", "plain") for r in saved})
        if len(looks) > 1:
            print(
                f"{args.from_json} mixes camera looks ({', '.join(looks)}): summarise one look per file",
                file=sys.stderr,
            )
            return 2
        print(table(summary, worlds, round(duration), looks[0]))
        return 0
    profiles, pilots = args.profile or list(PROFILES), args.pilot or list(PILOTS)
    seeds = range(args.first, args.first + args.worlds)
    jobs = [(pr, pi, s, args.duration, args.fps, args.look) for pr in profiles for s in seeds for pi in pilots]
    t0 = time.perf_counter()
    runs: list[dict[str, Any]] = []
    with ProcessPoolExecutor(max_workers=args.jobs) as pool:
        for i, r in enumerate(pool.map(one, jobs), 1):
            runs.append(r)
            flag = (
                f"ERROR {r['error']}"
                if "error" in r
                else (
                    f"coll {r['collisions']} view {100 * (r['in_view_fraction'] or 0):.0f}%"
                    f" err {r['follow_error_mean_m'] or math.nan:.2f} m"
                )
            )
            print(
                f"[{i}/{len(jobs)}] {r['profile']:16s} {r['pilot']:10s} random:{r['seed']:<3d} {flag} "
                f"({r['wall_s']} s)",
                file=sys.stderr,
                flush=True,
            )
    summary = {
        pr: {pi: summarise([r for r in runs if r["profile"] == pr and r["pilot"] == pi]) for pi in pilots}
        for pr in profiles
    }
    print(table(summary, args.worlds, args.duration, args.look))
    print(f"\nwall time {time.perf_counter() - t0:.0f} s with {args.jobs} process(es)")
    if args.json:
        args.json.write_text(json.dumps({"summary": summary, "runs": runs}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
