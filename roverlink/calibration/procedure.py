"""The guided calibration, in the order a careful builder works:

1. On a stand: each motor's direction (a short open-loop spin: the observer says which way the
   wheel turned) and each encoder's direction (which way it counted): motor_invert and
   encoder_invert, in the board's configuration, no re-flash.
2. On the stand: encoder counts per revolution, from the counts over N turns of each wheel that
   the observer counts.
3. On the floor: the wheel diameter, from a straight drive the observer measures (Ackermann: the
   end point's offset to the side also gives the steering centre trim).
4. Differential drive: the track width, from an in-place rotation the observer measures (with
   an IMU configured, its yaw measures it: roverlink.calibration.imu).
   Ackermann: the steering angle per servo step (and the trim again, precisely) from one drive
   at a servo step to each side; the servo's pulse span is set so the board's angles are the
   wheels' angles.

Each finding goes into the board's configuration at once (the next step needs it); the caller
shows the configuration before and after and saves it to EEPROM after confirmation, or puts the
old one back. The track width is not a board setting: it is the host's (a calibration file).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field

from host_sdk import Ackermann, DiffDrive, FeedbackSample, PidGains, Robot, RobotConfig
from host_sdk.enums import Capability
from host_sdk.odometry import Odometry
from host_sdk.profiles import get_profile, profile_for_example
from protocol.generated.messages import SetConfig
from roverlink.calibration import geometry
from roverlink.calibration.imu import DISAGREE, ImuObserver
from roverlink.calibration.observer import Observer
from roverlink.tuning.steps import command_wheel, gains_applied, wheel_count

SETTLE_S = 0.6
"""Wait after stopping before reading counts (the robot coasts to rest)."""


@dataclass
class CalibrationResult:
    config_before: RobotConfig
    config_after: RobotConfig
    track_before_m: float
    track_after_m: float
    wheelbase_m: float
    ackermann: bool
    findings: list[str] = field(default_factory=list)

    def kinematics(self) -> DiffDrive | Ackermann:
        """The robot's kinematics with the calibrated values (for Robot.connect(kinematics=...))."""
        c = self.config_after
        radius = c.wheel_diameter_um / 2e6
        if not self.ackermann:
            return DiffDrive(wheel_radius_m=radius, track_m=self.track_after_m, counts_per_rev=c.encoder_cpr)
        left = math.radians((c.steering_max_cdeg - c.steering_center_cdeg) / 100)
        right = math.radians((c.steering_center_cdeg - c.steering_min_cdeg) / 100)
        return Ackermann(
            wheelbase_m=self.wheelbase_m,
            wheel_radius_m=radius,
            counts_per_rev=c.encoder_cpr,
            max_steering_rad=max(left, right, 1e-3),
        )

    def changes(self) -> list[tuple[str, object, object]]:
        """(name, before, after) of every value that changed."""
        out: list[tuple[str, object, object]] = [
            (name, before, self.config_after.fields()[name])
            for name, before in self.config_before.fields().items()
            if self.config_after.fields()[name] != before
        ]
        if not self.ackermann and round(self.track_after_m, 4) != round(self.track_before_m, 4):
            out.append(("track_m (host)", round(self.track_before_m, 4), round(self.track_after_m, 4)))
        return out


class Calibration:
    """Runs the steps in the module docstring on `robot`, asking `observer`."""

    def __init__(
        self,
        robot: Robot,
        observer: Observer,
        *,
        revolutions: float = 5.0,
        distance_m: float = 2.0,
        turns: float = 1.0,
        track_m: float | None = None,
        wheelbase_m: float | None = None,
        say: Callable[[str], None] = print,
        progress: Callable[[str, float], None] | None = None,
        tick: Callable[[], None] | None = None,
    ) -> None:
        self.robot = robot
        self.tick = tick
        """Called at every FEEDBACK while the robot moves (reads sensors on a virtual clock)."""
        self.observer = observer
        self.revolutions = revolutions
        self.distance_m = distance_m
        self.turns = turns
        self.say = say
        self.progress = progress
        self.ackermann = not robot.identity.capabilities & Capability.DIFF_DRIVE
        profile = profile_for_example(robot.identity.robot_name)
        self.wheelbase_m = profile.wheelbase_m if profile is not None else 0.0
        if wheelbase_m is not None:  # the robot file's: its own robot, not the firmware's reference
            self.wheelbase_m = wheelbase_m
        default_track = profile.track_m if profile is not None else 0.0
        kin = robot.kinematics
        if track_m is None:
            track_m = kin.track_m if isinstance(kin, DiffDrive) else default_track
        self.track_m = track_m
        self.findings: list[str] = []
        if self.ackermann and not self.wheelbase_m and isinstance(kin, Ackermann):
            self.wheelbase_m = kin.wheelbase_m

    # -- motion primitives ----------------------------------------------------------------------
    @property
    def _config(self) -> RobotConfig:
        return self.robot.config

    def _speed(self, fraction: float) -> float:
        return self._config.max_wheel_speed_mm_s / 1000 * fraction

    def feedback(self) -> FeedbackSample:
        """The next FEEDBACK (and a tick)."""
        sample = self.robot.wait_feedback()
        if self.tick is not None:
            self.tick()
        return sample

    def _counts(self) -> tuple[int, ...]:
        return self.feedback().encoder_counts

    def _mpc(self) -> float:
        c = self._config
        return math.pi * c.wheel_diameter_um / 1e6 / c.encoder_cpr

    def _settle(self) -> tuple[int, ...]:
        self.robot.stop()
        end = self.robot.now() + SETTLE_S
        while self.robot.now() < end:
            self.robot.stop()
            self.feedback()
        return self._counts()

    def _run_until(
        self, command: Callable[[], None], done: Callable[[tuple[int, ...], float], float], what: str
    ) -> None:
        """Arm, then repeat `command` until `done(counts, seconds since armed)` (a progress
        fraction) reaches 1; stop."""
        robot = self.robot
        robot.arm()
        try:
            begin = robot.now()
            limit = begin + 120.0
            while True:
                command()
                fraction = done(self._counts(), robot.now() - begin)
                if self.progress is not None:
                    self.progress(what, min(1.0, fraction))
                if fraction >= 1.0:
                    break
                if robot.now() > limit:
                    raise TimeoutError(f"{what}: not done after 120 s (is the wheel blocked?)")
        finally:
            robot.stop()

    # -- steps ------------------------------------------------------------------------------------
    def directions(self) -> None:
        """Step 1 (on the stand)."""
        self.observer.place(True)
        for wheel in range(wheel_count(self.robot)):
            config = self._config
            gains = self.robot.pid(wheel)
            open_loop = PidGains(kp=0.0, ki=0.0, kd=0.0, kf=gains.kf or 1.0, ks=gains.ks)
            self.observer.mark()
            before = self._counts()
            with gains_applied(self.robot, wheel, open_loop):
                self._run_until(
                    functools.partial(command_wheel, self.robot, wheel, self._speed(0.15)),
                    lambda _c, elapsed: elapsed / 1.0,
                    f"wheel {wheel}: direction",
                )
                after = self._settle()
            self.robot.disarm()
            forward = self.observer.turned_forward(wheel)
            delta = after[wheel] - before[wheel]
            motor, encoder = geometry.direction_bits(config.motor_invert, config.encoder_invert, wheel, forward, delta)
            self.findings.append(
                f"wheel {wheel}: motor turned {'forward' if forward else 'backward'}, encoder counted {delta:+d}"
                + (": motor_invert fixed" if motor != config.motor_invert else "")
                + (": encoder_invert fixed" if encoder != config.encoder_invert else "")
            )
            if (motor, encoder) != (config.motor_invert, config.encoder_invert):
                self.robot.set_config(motor_invert=motor, encoder_invert=encoder)

    def counts_per_revolution(self) -> None:
        """Step 2 (on the stand): each wheel turns about `revolutions` times."""
        results = []
        for wheel in range(wheel_count(self.robot)):
            cpr = self._config.encoder_cpr
            self.observer.mark()
            start = self._counts()
            target = self.revolutions * cpr
            self._run_until(
                functools.partial(command_wheel, self.robot, wheel, self._speed(0.2)),
                functools.partial(_turned, wheel=wheel, start=start, target=target),
                f"wheel {wheel}: {self.revolutions:g} turns",
            )
            counts = self._settle()[wheel] - start[wheel]
            self.robot.disarm()
            turned = self.observer.revolutions(wheel)
            results.append(geometry.counts_per_rev(counts, turned))
            self.findings.append(f"wheel {wheel}: {counts} counts in {turned:.3f} turns = {results[-1]} per turn")
        cpr = round(sum(results) / len(results))
        if cpr != self._config.encoder_cpr:
            self.robot.set_config(encoder_cpr=cpr)

    def _covered(self, counts: tuple[int, ...], _elapsed: float, *, start: tuple[int, ...], distance_m: float) -> float:
        return self._distance(start, counts) / distance_m

    def _distance(self, start: tuple[int, ...], now: tuple[int, ...]) -> float:
        wheels = wheel_count(self.robot)
        return sum(now[w] - start[w] for w in range(wheels)) / wheels * self._mpc()

    def wheel_diameter(self) -> None:
        """Step 3 (on the floor): a straight drive of `distance_m`, measured."""
        self.observer.place(False)
        self.observer.mark()
        start = self._counts()
        speed = self._speed(0.25)

        def forward() -> None:
            if self.ackermann:
                self.robot.drive_ackermann(speed, 0.0)
            else:
                self.robot.set_wheel_speeds(speed, speed)

        self._run_until(
            forward, lambda c, _t: self._distance(start, c) / self.distance_m, f"{self.distance_m:g} m ahead"
        )
        odometry = self._distance(start, self._settle())
        self.robot.disarm()
        forward_m, left_m = self.observer.displacement()
        arc, kappa = geometry.arc_through(forward_m, left_m)
        diameter = round(geometry.scaled(self._config.wheel_diameter_um, odometry, arc))
        self.findings.append(
            f"drove {odometry:.3f} m by odometry, {arc:.3f} m measured: wheel {diameter / 1000:.2f} mm"
        )
        if self.ackermann and self.wheelbase_m:
            delta = math.degrees(math.atan(kappa * self.wheelbase_m))
            self._trim(-delta, f"drifted {left_m * 100:+.1f} cm sideways (wheels at {delta:+.2f} deg)")
        if diameter != self._config.wheel_diameter_um:
            self.robot.set_config(wheel_diameter_um=diameter)

    def _trim(self, servo_deg: float, why: str) -> None:
        c = self._config
        shift = round(servo_deg * 100)
        if shift == 0:
            return
        self.findings.append(
            f"steering: {why}: centre {c.steering_center_cdeg} -> {c.steering_center_cdeg + shift} cdeg"
        )
        self.robot.set_config(
            steering_center_cdeg=c.steering_center_cdeg + shift,
            steering_min_cdeg=max(0, c.steering_min_cdeg + shift),
            steering_max_cdeg=min(SetConfig.STEERING_MAX_CDEG_MAX, c.steering_max_cdeg + shift),
        )

    def track(self) -> None:
        """Step 4, differential drive: `turns` full turns in place, measured."""
        self.observer.mark()
        start = self._counts()
        speed = self._speed(0.15)
        target = 2 * math.pi * self.turns

        def heading(c: tuple[int, ...]) -> float:
            return ((c[1] - start[1]) - (c[0] - start[0])) * self._mpc() / self.track_m

        self._run_until(
            lambda: self.robot.set_wheel_speeds(-speed, speed),
            lambda c, _t: heading(c) / target,
            f"{self.turns:g} turn in place",
        )
        odometry = heading(self._settle())
        self.robot.disarm()
        measured = math.radians(self.observer.rotation_deg())
        track = geometry.track_width(self.track_m, odometry, measured)
        by = "measured"
        imu = self.observer.last if isinstance(self.observer, ImuObserver) else None
        if imu is not None:
            by = (
                f"by the IMU's yaw (its gyro: {math.degrees(imu.gyro_rad):.1f} deg; "
                f"yaw drift at rest {math.degrees(imu.drift_rad_s):+.3f} deg/s)"
            )
        self.findings.append(
            f"turned {math.degrees(odometry):.1f} deg by odometry, {math.degrees(measured):.1f} deg {by}: "
            f"track {track * 1000:.1f} mm"
        )
        if imu is not None and imu.disagreement > DISAGREE:
            self.findings.append(
                f"warning: the IMU's yaw and its gyro disagree by {imu.disagreement * 100:.1f} %: a magnetic "
                "disturbance near the robot, or the gyro's scale; measure the turn yourself to be sure (--no-imu)"
            )
        self.track_m = track

    def steering(self, passes: int = 2) -> None:
        """Step 4, Ackermann: one drive a servo step to each side gives the ratio and the trim;
        a second pass measures what is left (the servo's own steps round the first answer)."""
        for _ in range(passes):
            if not self._steering_pass():
                break

    def _steering_pass(self) -> bool:
        """One pair of drives; True if it changed something."""
        c = self._config
        step_deg = (c.steering_step_cdeg or 1000) / 100
        kappas = []
        for side in (1, -1):
            angle = math.radians(step_deg) * side
            radius = self.wheelbase_m / math.tan(abs(angle))
            arc_m = min(radius * math.pi / 2, 3.0)  # a quarter circle
            self.observer.mark()
            start = self._counts()
            self._run_until(
                functools.partial(self.robot.drive_ackermann, self._speed(0.2), angle),
                functools.partial(self._covered, start=start, distance_m=arc_m),
                f"quarter circle {'left' if side > 0 else 'right'}",
            )
            self._settle()
            self.robot.disarm()
            kappas.append(geometry.arc_through(*self.observer.displacement())[1])
        ratio, trim = geometry.steering_from_circles(kappas[0], kappas[1], self.wheelbase_m, step_deg)
        self.findings.append(f"steering: {ratio:.3f} wheel degrees per servo degree, centre off by {trim:+.2f} deg")
        changed = round(trim * 100) != 0
        self._trim(trim, "turning circles")
        if abs(ratio - 1) > 0.003:
            c = self._config
            lo, hi = geometry.servo_span_for(c.servo_min_us, c.servo_max_us, c.steering_center_cdeg, ratio)
            beyond = _pulse_beyond_range(lo, hi)
            if beyond:
                # The board maps 0..180 degrees linearly onto servo_min_us..servo_max_us: a weak
                # linkage needs a span wider than the spec's pulses allow, so its angles stay off.
                self.findings.append(
                    f"servo pulse span for that linkage: {lo}..{hi} us, but {beyond}: the span is left at "
                    f"{c.servo_min_us}..{c.servo_max_us} us, so the board's steering angles are {1 / ratio:.2f}x the "
                    "wheels'; a longer servo horn or a stiffer linkage brings the ratio nearer 1"
                )
            elif (lo, hi) != (c.servo_min_us, c.servo_max_us):
                self.findings.append(f"servo pulse span {c.servo_min_us}..{c.servo_max_us} -> {lo}..{hi} us")
                self.robot.set_config(servo_min_us=lo, servo_max_us=hi)
                changed = True
        return changed

    def run(self) -> CalibrationResult:
        before = self.robot.read_config()
        track_before = self.track_m
        self.directions()
        self.counts_per_revolution()
        self.wheel_diameter()
        if self.ackermann:
            if self.wheelbase_m:
                self.steering()
        else:
            self.track()
        return CalibrationResult(
            config_before=before,
            config_after=self.robot.read_config(),
            track_before_m=track_before,
            track_after_m=self.track_m,
            wheelbase_m=self.wheelbase_m,
            ackermann=self.ackermann,
            findings=list(self.findings),
        )


@dataclass(frozen=True, slots=True)
class Check:
    what: str
    odometry: float
    measured: float
    unit: str
    by: str = "measured"
    """Who measured: a person (or the emulator's truth), or the IMU."""

    @property
    def error(self) -> float:
        """|odometry - measured| / |measured|."""
        return abs(self.odometry - self.measured) / abs(self.measured) if self.measured else math.inf

    def line(self) -> str:
        return (
            f"{self.what}: odometry {self.odometry:.3f} {self.unit}, {self.by} {self.measured:.3f} {self.unit} "
            f"({self.error * 100:.2f} %)"
        )


def verify(cal: Calibration, result: CalibrationResult) -> list[Check]:
    """Drive `distance_m` straight and one full turn with the calibrated kinematics' odometry,
    and compare with what the observer measures."""
    robot = cal.robot
    odometry = Odometry(result.kinematics())

    def integrate(sample: FeedbackSample) -> None:
        odometry.update(sample.encoder_counts, sample.mcu_time_us, sample.steering_rad)

    unsubscribe = robot.on_feedback(integrate)
    checks = []
    try:
        speed = cal._speed(0.25)
        cal.observer.place(False)
        cal.observer.mark()
        cal.feedback()
        odometry.reset()

        def straight() -> None:
            if cal.ackermann:
                robot.drive_ackermann(speed, 0.0)
            else:
                robot.set_wheel_speeds(speed, speed)

        cal._run_until(straight, lambda _c, _t: odometry.pose.x_m / cal.distance_m, "check: straight")
        cal._settle()
        robot.disarm()
        forward, left = cal.observer.displacement()
        pose = odometry.pose
        checks.append(Check("straight drive", math.hypot(pose.x_m, pose.y_m), math.hypot(forward, left), "m"))
        cal.observer.mark()
        cal.feedback()
        odometry.reset()
        step = math.radians((result.config_after.steering_step_cdeg or 1000) / 100)

        def turn() -> None:
            if cal.ackermann:
                robot.drive_ackermann(cal._speed(0.2), step)
            else:
                robot.set_wheel_speeds(-cal._speed(0.15), cal._speed(0.15))

        cal._run_until(turn, lambda _c, _t: odometry.pose.theta_rad / (2 * math.pi), "check: full turn")
        cal._settle()
        robot.disarm()
        by = "by the IMU" if isinstance(cal.observer, ImuObserver) else "measured"
        turned = cal.observer.rotation_deg()
        checks.append(Check("full turn", math.degrees(odometry.pose.theta_rad), turned, "deg", by))
    finally:
        unsubscribe()
    return checks


def _turned(counts: tuple[int, ...], _elapsed: float, *, wheel: int, start: tuple[int, ...], target: float) -> float:
    return (counts[wheel] - start[wheel]) / target


def restore(robot: Robot, config: RobotConfig) -> None:
    """Put a configuration back (the calibration was not kept)."""
    robot.set_config(**dataclasses.asdict(config))


__all__ = ["Calibration", "CalibrationResult", "Check", "get_profile", "restore", "verify"]


def _pulse_beyond_range(lo_us: int, hi_us: int) -> str:
    """Which of a servo span's ends the board's configuration cannot hold ("" if both fit)."""
    fields = {f.name: f for f in SetConfig.FIELDS}
    out = []
    for name, value in (("servo_min_us", lo_us), ("servo_max_us", hi_us)):
        f = fields[name]
        if not f.lo <= value <= f.hi:
            out.append(f"{name} = {value} is outside the board's {f.lo:g}..{f.hi:g} us")
    return " and ".join(out)
