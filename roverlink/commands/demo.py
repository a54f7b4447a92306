"""`roverlink demo`: connect, arm, drive a 1 m square, compare odometry with the truth.

With no arguments it runs the in-process emulator of the diff-drive car on the wall clock, so it
needs no hardware; `--url`/`--port` points it at a board (or a pty from `roverlink emulate`).
An Ackermann robot cannot turn in place: it drives the square with quarter-circle corners at its
tightest steering.
"""

from __future__ import annotations

import argparse
import importlib
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, TextIO
from urllib.parse import quote

from host_sdk import (
    PROFILES,
    Ackermann,
    DiffDrive,
    FeedbackSample,
    LinkStatistics,
    Pose,
    Robot,
    RobotDescription,
    RoverLinkError,
    UnsupportedError,
    enums,
)
from host_sdk.profiles import steering_limits
from roverlink import argtypes, say
from roverlink.interactive import add_profile_args, add_url_args, warn_mismatches

_TURN_TOLERANCE_RAD = math.radians(1.0)


@dataclass
class Track:
    """Odometry and (emulator only) ground truth, sampled while driving, in the start frame."""

    odometry: list[tuple[float, float]] = field(default_factory=list)
    truth: list[tuple[float, float]] = field(default_factory=list)


@dataclass
class DemoResult:
    pose: Pose
    truth: tuple[float, float, float] | None
    """x, y, theta of the plant in the frame the square started in (emulator only)."""
    stats: LinkStatistics
    track: Track
    duration_s: float
    side_m: float = 1.0
    """The side of the square driven."""
    corner_radius_m: float = 0.0
    """0: the corners are turns in place; an Ackermann robot's: its tightest turning radius."""

    @property
    def course(self) -> str:
        """What was driven, in words: the square, its corners and the size of the path."""
        corners = "turns in place" if not self.corner_radius_m else f"{self.corner_radius_m:.2f} m radius corners"
        points = self.track.truth or self.track.odometry
        if not points:
            return f"{self.side_m:g} m square, {corners}"
        xs, ys = zip(*points, strict=True)
        size = f"{max(xs) - min(xs):.2f} x {max(ys) - min(ys):.2f} m"
        return f"{self.side_m:g} m square, {corners}: a {size} path"

    @property
    def position_error_m(self) -> float | None:
        if self.truth is None:
            return None
        return math.hypot(self.pose.x_m - self.truth[0], self.pose.y_m - self.truth[1])

    @property
    def heading_error_rad(self) -> float | None:
        if self.truth is None:
            return None
        d = self.pose.theta_rad - self.truth[2]
        return math.atan2(math.sin(d), math.cos(d))


class _Truth:
    """Ground truth of the emulator, expressed in the frame where the square started."""

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        self.origin = self._raw()

    def _raw(self) -> tuple[float, float, float] | None:
        if self.robot.emulator is None:
            return None
        transport = self.robot.transport
        locked = getattr(transport, "locked", None)
        assert locked is not None
        with locked() as emu:
            p = emu.truth.plant
            return (p.x_m, p.y_m, p.theta_rad)

    def now(self) -> tuple[float, float, float] | None:
        raw = self._raw()
        if raw is None or self.origin is None:
            return None
        x0, y0, t0 = self.origin
        dx, dy = raw[0] - x0, raw[1] - y0
        c, s = math.cos(-t0), math.sin(-t0)
        return (c * dx - s * dy, s * dx + c * dy, raw[2] - t0)


class _Progress:
    def __init__(self, out: TextIO, quiet: bool) -> None:
        self.out = out
        self.quiet = quiet
        self.tty = out.isatty()
        self._last = -1.0

    def show(
        self,
        now: float,
        *,
        leg: int,
        what: str,
        pose: Pose,
        truth: tuple[float, float, float] | None,
        stats: LinkStatistics,
    ) -> None:
        if self.quiet or now - self._last < (0.1 if self.tty else 1.0):
            return
        self._last = now
        line = f"leg {leg}/4 {what:<8} x={pose.x_m:+.3f} y={pose.y_m:+.3f} th={math.degrees(pose.theta_rad):+7.1f}deg"
        if truth is not None:
            line += f" | truth x={truth[0]:+.3f} y={truth[1]:+.3f}"
        line += f" | rx {stats.frames_received} tx {stats.frames_sent} bad {_bad(stats)}"
        if self.tty:
            self.out.write("\r" + line[:150].ljust(150))
        else:
            self.out.write(line + "\n")
        self.out.flush()

    def done(self) -> None:
        if self.tty and not self.quiet:
            self.out.write("\n")


def _bad(stats: LinkStatistics) -> int:
    return stats.crc_errors + stats.cobs_errors + stats.length_errors + stats.unknown_ids + stats.value_errors


def drive_square(
    robot: Robot, side_m: float = 1.0, speed_m_s: float = 0.3, turn_rad_s: float = 1.2, out: TextIO | None = None
) -> DemoResult:
    """Drive a square (counter-clockwise) on odometry; returns the end pose, truth and statistics."""
    out = out or sys.stdout
    kin = robot.kinematics
    if kin is None:
        raise RoverLinkError("the demo needs the robot's kinematics: pass --profile")
    square = _Square(robot, kin, out, side_m=side_m, speed_m_s=speed_m_s, turn_rad_s=turn_rad_s)
    heading = 0.0
    for leg in range(1, 5):
        square.straight(leg, heading)
        heading += math.pi / 2
        square.corner(leg, heading)
    # Stop and let the robot come to rest before comparing.
    for _ in range(25):
        robot.stop()
        robot.wait_feedback(1.0)
    robot.disarm()
    robot.sleep(0.3)
    square.progress.done()
    radius = _ackermann_radius(robot, kin) if isinstance(kin, Ackermann) else 0.0
    return DemoResult(
        robot.odometry.pose, square.truth.now(), robot.stats, square.track, robot.now() - square.start, side_m, radius
    )


class _Square:
    """One drive around the square: every control step is checked against the time budget, shown
    on the progress line and recorded in the track."""

    def __init__(
        self,
        robot: Robot,
        kin: DiffDrive | Ackermann,
        out: TextIO,
        *,
        side_m: float,
        speed_m_s: float,
        turn_rad_s: float,
    ) -> None:
        self.robot = robot
        self.kin = kin
        self.side_m = side_m
        self.turn_rad_s = turn_rad_s
        self.progress = _Progress(out, quiet=False)
        robot.odometry.reset()
        self.truth = _Truth(robot)
        self.track = Track()
        self.start = robot.now()
        limit = robot.config.max_wheel_speed_mm_s / 1000
        self.speed = min(speed_m_s, 0.8 * limit)
        self.accel = robot.config.decel_limit_mm_s2 / 1000
        # However the robot behaves, the demo ends: four sides and four corners at a quarter of the
        # speed asked for, and half a minute to spare.
        self.budget_s = 4 * (side_m / self.speed + math.pi / 2 / min(turn_rad_s, 0.5)) * 4 + 30

    def step(self, leg: int, what: str, linear: float, angular: float, steering: float | None = None) -> FeedbackSample:
        robot = self.robot
        if robot.now() - self.start > self.budget_s:
            raise RoverLinkError(
                f"the square did not finish within {self.budget_s:.0f} s (stuck on leg {leg}, {what}): "
                "is the robot blocked, or its encoders unplugged?"
            )
        if steering is None:
            robot.drive(linear, angular, clamp=True)
        else:
            robot.drive_ackermann(linear, steering, clamp=True)
        sample = robot.wait_feedback(1.0)
        pose = sample.pose
        assert pose is not None
        t = self.truth.now()
        self.track.odometry.append((pose.x_m, pose.y_m))
        if t is not None:
            self.track.truth.append((t[0], t[1]))
        self.progress.show(robot.now(), leg=leg, what=what, pose=pose, truth=t, stats=robot.stats)
        return sample

    def straight(self, leg: int, heading: float) -> None:
        """Hold the heading, slowing down so the ramp ends at the corner (an Ackermann corner starts
        its turning radius before the side's end)."""
        p0 = self.robot.odometry.pose
        length = self.side_m
        if isinstance(self.kin, Ackermann):
            length = self.side_m - _ackermann_radius(self.robot, self.kin)
        while True:
            p = self.robot.odometry.pose
            left = length - math.hypot(p.x_m - p0.x_m, p.y_m - p0.y_m)
            if left <= 0.002:
                return
            v = min(self.speed, math.sqrt(2 * self.accel * 0.5 * left) + 0.02)
            if isinstance(self.kin, DiffDrive):
                self.step(leg, "straight", v, 3.0 * _wrap(heading - p.theta_rad))
            else:
                self.step(leg, "straight", v, 0.0, 0.0)

    def corner(self, leg: int, heading: float) -> None:
        """Turn to the heading: in place for a diff drive, at the tightest steering for Ackermann."""
        if isinstance(self.kin, DiffDrive):
            while True:
                err = _wrap(heading - self.robot.odometry.pose.theta_rad)
                if abs(err) < _TURN_TOLERANCE_RAD:
                    return
                w = math.copysign(min(self.turn_rad_s, 3.0 * abs(err) + 0.15), err)
                self.step(leg, "turn", 0.0, w)
        steer = _ackermann_steer(self.robot)
        while True:
            err = _wrap(heading - self.robot.odometry.pose.theta_rad)
            if err < _TURN_TOLERANCE_RAD:
                return
            self.step(leg, "turn", min(self.speed, 0.25), 0.0, steer)


def _ackermann_steer(robot: Robot) -> float:
    _right, left = steering_limits(robot.config)
    step = robot.config.steering_step_cdeg
    if step > 0:  # the servo only takes centre + k * step: use the largest step within the limit
        k = math.floor(math.degrees(left) * 100 / step + 1e-9)
        return math.radians(k * step / 100) if k > 0 else left
    return left


def _ackermann_radius(robot: Robot, kin: Ackermann) -> float:
    return kin.wheelbase_m / math.tan(_ackermann_steer(robot))


def _wrap(a: float) -> float:
    return math.atan2(math.sin(a), math.cos(a))


def format_report(result: DemoResult) -> str:
    p, t = result.pose, result.truth
    lines = ["", "Odometry against ground truth (start frame)" if t else "Odometry (no ground truth on hardware)"]
    if t is not None:
        lines.append(f"  {'':<14}{'odometry':>10}{'truth':>10}{'error':>12}")
        lines.append(f"  {'x':<14}{p.x_m:>9.3f}m{t[0]:>9.3f}m{(p.x_m - t[0]) * 1000:>10.1f}mm")
        lines.append(f"  {'y':<14}{p.y_m:>9.3f}m{t[1]:>9.3f}m{(p.y_m - t[1]) * 1000:>10.1f}mm")
        th, tt = math.degrees(p.theta_rad), math.degrees(t[2])
        lines.append(f"  {'heading':<14}{th:>8.2f}deg{tt:>7.2f}deg{th - tt:>9.2f}deg")
        pe, he = result.position_error_m, result.heading_error_rad
        assert pe is not None and he is not None
        lines.append(f"  position error {pe * 1000:.1f} mm, heading error {math.degrees(abs(he)):.2f} deg")
    else:
        lines.append(f"  x {p.x_m:.3f} m, y {p.y_m:.3f} m, heading {math.degrees(p.theta_rad):.2f} deg")
    s = result.stats
    lines += ["", f"Link statistics ({result.duration_s:.1f} s of driving)"]
    rows = [
        ("frames sent / received", f"{s.frames_sent} / {s.frames_received}"),
        ("bytes sent / received", f"{s.bytes_sent} / {s.bytes_received}"),
        ("feedback frames", f"{s.feedback_received}"),
        ("setpoints (keep-alives)", f"{s.setpoints_sent} ({s.keepalives_sent})"),
        (
            "CRC / COBS / length errors",
            f"{s.crc_errors} / {s.cobs_errors} / {s.length_errors}",
        ),
        ("unknown ids / value errors", f"{s.unknown_ids} / {s.value_errors}"),
        ("seq gaps (frames lost)", f"{s.seq_gaps}"),
        ("requests / retries / timeouts", f"{s.requests_sent} / {s.retries} / {s.request_timeouts}"),
        ("NACKs", ", ".join(f"{k} {v}" for k, v in sorted(s.nacks.items())) or "0"),
        ("resets detected / reconnects", f"{s.resets_detected} / {s.reconnects}"),
        ("connect to ready", f"{s.connect_time_s * 1000:.1f} ms" if s.connect_time_s is not None else "-"),
    ]
    if s.rtt is not None:
        r = s.rtt
        rows.append(
            (
                "round trip (PING/PONG)",
                f"min {r.min_s * 1000:.2f} / mean {r.mean_s * 1000:.2f} / max {r.max_s * 1000:.2f} ms ({r.samples})",
            )
        )
    # The offset between the clocks is not shown: the board's counts from its boot, the host's from
    # the machine's, so its size says nothing; how fast the board's runs is what time sync corrects.
    if s.clock_drift_ppm is not None:
        rows.append(("board clock drift", f"{s.clock_drift_ppm:+.1f} ppm against the host's (time sync corrects it)"))
    width = max(len(k) for k, _ in rows)
    lines += [f"  {k:<{width}}  {v}" for k, v in rows]
    return "\n".join(lines)


def plot_module() -> Any:
    """matplotlib.pyplot on the file backend; RoverLinkError with the install command if it is missing."""
    try:
        matplotlib = importlib.import_module("matplotlib")
        matplotlib.use("Agg")
        return importlib.import_module("matplotlib.pyplot")
    except ImportError:
        raise RoverLinkError(f"--plot needs matplotlib: install it with `{_install_hint('plot')}`") from None


def _install_hint(extra: str) -> str:
    """The command that installs an extra into the Python running this: from the checkout if this
    is one (a venv made by scripts/demo.sh, say), else from the package index."""
    root = Path(__file__).resolve().parents[2]
    if (root / "pyproject.toml").is_file():
        return f"{sys.executable} -m pip install -e '{root}[{extra}]'"
    return f"{sys.executable} -m pip install 'roverlink[{extra}]'"


def figure(result: DemoResult, robot: str = "") -> Any:
    """Odometry against ground truth: the truth a wide pale band, odometry a thin dark line on top,
    so both show where they lie on each other; the title says what was driven (`robot`: whose)."""
    plt = plot_module()
    fig, ax = plt.subplots(figsize=(6, 6))
    if result.track.truth:
        xs, ys = zip(*result.track.truth, strict=True)
        ax.plot(xs, ys, label="ground truth (emulator)", color="tab:blue", linewidth=6, alpha=0.35, zorder=2)
    if result.track.odometry:
        xs, ys = zip(*result.track.odometry, strict=True)
        ax.plot(xs, ys, label="odometry (SDK)", color="tab:red", linewidth=1.2, zorder=3)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.grid(True)
    title = f"RoverLink demo{f' ({robot})' if robot else ''}: {result.course}"
    if result.position_error_m is not None:
        title += f"\nend error {result.position_error_m * 1000:.1f} mm"
    ax.set_title(title)
    ax.legend()
    return fig


def plot(result: DemoResult, path: str, robot: str = "") -> None:
    """`figure` as a PNG at `path`."""
    fig = figure(result, robot)
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plot_module().close(fig)


def add_parser(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    p = sub.add_parser(
        "demo",
        help="drive a 1 m square (in the emulator unless --url is given) and report",
        description="Connect, arm and drive a square on odometry (an emulated robot unless --url is given), then "
        "compare odometry with ground truth and show the link statistics.",
    )
    add_profile_args(p, help_text="robot (default: diffdrive-tb6612)")
    add_url_args(p, without="the emulator", port_alias=True)
    p.add_argument(
        "--mode", choices=("stream", "lockstep"), default=None, help="feedback mode (default: the profile's)"
    )
    p.add_argument("--seed", type=argtypes.SEED, default=0, help="emulator seed (default 0)")
    p.add_argument("--faults", default="", help="emulator fault spec, e.g. bitflip=1e-4,drop=1e-4")
    p.add_argument("--fast", action="store_true", help="emulator on its virtual clock: as fast as the CPU allows")
    p.add_argument(
        "--side", type=argtypes.number(0.1, 10, "m"), default=1.0, help="side of the square, 0.1..10 m (default 1)"
    )
    p.add_argument(
        "--speed",
        type=argtypes.number(0.05, 2, "m/s"),
        default=0.3,
        help="straight-line speed, 0.05..2 m/s, at most 80%% of the board's limit (default 0.3)",
    )
    p.add_argument("--plot", metavar="FILE.png", default=None, help="draw odometry against truth (needs matplotlib)")
    p.set_defaults(func=cmd_demo)


def cmd_demo(args: argparse.Namespace) -> int:
    robot_file: RobotDescription | None = args.robot
    profile = args.profile or "diffdrive-tb6612"
    if robot_file is not None:  # the file's name, feedback and capabilities stand for the profile's
        profile, own_mode, caps = robot_file.name, robot_file.feedback.mode, robot_file.capabilities()
    else:
        own_mode, caps = PROFILES[profile].feedback_mode.name, PROFILES[profile].capabilities
    mode: Literal["stream", "lockstep"] = "lockstep" if (args.mode or own_mode).lower() == "lockstep" else "stream"
    if mode == "lockstep" and args.url is None and not caps & enums.Capability.LOCKSTEP:
        say.error(f"{profile} has no lockstep feedback: run the demo with --mode stream")
        return 2
    if args.plot:  # before any driving: a missing matplotlib must not cost the whole course
        try:
            plot_module()
        except RoverLinkError as exc:
            say.error(f"{exc}")
            return 1
    if args.url is None:
        query = f"seed={args.seed}&clock={'virtual' if args.fast else 'real'}"
        if args.faults:
            query += "&faults=" + quote(args.faults, safe=",")
        # A robot file is emulated from the file itself (its geometry is the plant's).
        url = f"emu://?robot={quote(robot_file.path)}&{query}" if robot_file else f"emu://{profile}?{query}"
    else:
        url = args.url
    # On a URL of the user's, the robot is the board's own until it answers (no profile assumed).
    named = robot_file is not None or args.profile is not None or args.url is None
    print(f"RoverLink demo: {profile + ' on ' if named else ''}{url} ({mode} feedback)")
    try:
        with Robot.connect(
            url,
            profile=profile if named and robot_file is None else None,
            robot=robot_file,
            allow_mismatch=args.allow_mismatch,
            baud=args.baud,
            mode=mode,
        ) as robot:
            warn_mismatches(robot)
            ident = robot.identity
            s = robot.stats
            ready = f"{s.connect_time_s * 1000:.1f} ms" if s.connect_time_s is not None else "?"
            print(
                f"connected to {ident.robot_name} firmware {ident.version} on {ident.board.name}, "
                f"boot_id 0x{ident.boot_id:08X}, ready in {ready}; arming"
            )
            robot.arm()
            result = drive_square(robot, args.side, args.speed)
    except UnsupportedError as exc:
        if exc.capability is enums.Capability.LOCKSTEP:
            say.error(f"the board on {url} has no lockstep feedback: run the demo with --mode stream")
        else:
            say.error(f"{exc}")
        return 1
    except RoverLinkError as exc:
        say.error(f"{exc}")
        return 1
    print(format_report(result))
    if args.plot:
        try:
            plot(result, args.plot, f"{profile}, {mode} feedback")
        except RoverLinkError as exc:
            say.error(f"{exc}")
            return 1
        print(f"\nplot written to {args.plot}")
    return 0
