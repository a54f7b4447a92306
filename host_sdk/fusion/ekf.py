"""Wheel odometry + IMU fusion: an extended Kalman filter over the planar pose and the gyro's bias.

    ekf = PoseEkf()
    ekf.add_gyro(t, sample.gyro[2])              # every IMU sample (rad/s about z)
    ekf.add_odometry(t, ds_m, dtheta_rad)        # every wheel odometry increment (robot.odometry)
    ekf.add_heading(t, compass_heading(mag))     # optional: a magnetometer heading
    ekf.pose                                     # FusedPose: x, y, theta, gyro bias, covariance, slip

State: x, y, theta (the odometry frame), the gyro's z bias b, the scale error k of the wheels' turn
(a track width or steering calibration a few per cent off makes every turn read long or short),
psi, the offset between the odometry frame and the magnetometer's frame, e, how far the wheels'
own heading (the sum of their turns since the pose was set) is from the true heading, the
compass's error as a function of the heading (the cos and sin coefficients of its first two
harmonics, and c, what they leave), and d, how much the wheels over-read the distance while they
slip.

- **Prediction**, at each odometry increment: the heading turns by the gyro's integral over the
  interval less the bias (a gyro does not slip); the position moves the wheels' distance (less d)
  along the mid-interval heading. Gyro noise (angle random walk), the bias random walk and the
  wheels' distance noise feed the covariance. e grows by k times the turn, plus the wheels' own
  turn noise: a random walk in the turn and in the distance, and a transient where the turn rate
  changes (tyres slip, a steering servo is still slewing).
- **The wheels' heading as a measurement**: it equals theta + e, give or take an encoder count and
  the timing between the two sensors (the wheels' heading leads or lags the gyro's by the rate
  times the offset between their clocks). Neither error adds up: a heading the wheels measured
  to a count a minute ago is still right to a count. Standing still or driving straight pins the
  bias down, turns teach k, and when the wheels are good (no slip, k learnt) the fused heading
  follows them instead of a gyro whose bias random-walks.
- **Slip**: one step beyond a chi-square gate (99 %), or the wheels drifting away from the gyro
  step after step (a tyre spinning through a whole turn: the running average of the disagreement
  beyond what white noise leaves, 99.9 %). The step is flagged, e forgets what it was (the wheels'
  heading counts again from the gyro's, and neither b nor k learns from the slip), and the
  distance is doubted for a while (d, `slip_distance_noise` for `slip_time_s`).
- **Magnetometer heading** (optional): heading = theta + psi + f(theta) + c + noise. An
  uncalibrated compass is several degrees off, by an amount that depends on where the robot faces
  and is the same each time it faces that way: a hard-iron offset shifts the field's circle, which
  is a cos and sin of the heading, soft iron stretches it, twice the heading. f holds those four
  coefficients, learnt as the robot turns (gyro and wheels know the heading, the compass's
  readings then trace f); c is what they leave, changing only as the robot turns
  (`heading_correlation_rad`). A compass read at 200 Hz while standing still thus tells the filter
  nothing new after its first sample.

Without gyro samples in an interval the filter falls back to the wheels' turn (pure odometry).
"""

from __future__ import annotations

import bisect
import math
from collections import deque
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from host_sdk.errors import CommandRangeError
from host_sdk.fusion.ekf_params import EkfParams

F64 = NDArray[np.float64]
X, Y, TH, B, K, PSI, E, C, D = range(9)
HARMONICS = range(9, 13)
"""The compass error's harmonics: cos and sin of the heading (hard iron), of twice the heading (soft iron)."""
N = 13
PAUSE_S = 0.5
"""A gap in the gyro's samples this long is a pause: nothing is integrated across it."""
GYRO_HISTORY = 4096
"""At most this many gyro samples are kept (20 s at 200 Hz): those since the last odometry step, to
integrate up to steps that come after them (FEEDBACK queued while the IMU was read)."""
UNKNOWN = math.pi**2
"""Variance of a state nothing is known about: the compass frame's offset before the first heading,
the wheels' heading error after a slip."""
DISAGREEMENT_WEIGHT = 0.05
"""Weight of a step in the running average of the wheels' disagreement with the gyro (about 20 steps)."""


@dataclass(frozen=True, slots=True)
class FusedPose:
    time_s: float
    x_m: float
    y_m: float
    theta_rad: float
    """Heading in the odometry frame, unwrapped."""
    gyro_bias_rad_s: float
    turn_scale_error: float
    """How much the wheels over-read turns (0.05: by 5 %)."""
    covariance: F64
    """3 x 3 covariance of (x, y, theta)."""
    slipping: bool
    """The wheels disagreed with the gyro on the last step."""

    @property
    def heading_sigma_rad(self) -> float:
        return math.sqrt(max(float(self.covariance[2, 2]), 0.0))


def compass_heading(mag: tuple[float, float, float] | tuple[int, int, int]) -> float:
    """Heading of a level magnetometer (x forward, y left), counter-clockwise, up to a constant."""
    return -math.atan2(mag[1], mag[0])


class PoseEkf:
    def __init__(
        self,
        params: EkfParams | None = None,
        *,
        x_m: float = 0.0,
        y_m: float = 0.0,
        theta_rad: float = 0.0,
        time_s: float = 0.0,
    ) -> None:
        self.params = p = params or EkfParams()
        self.x: F64 = np.zeros(N)
        self.x[[X, Y, TH]] = x_m, y_m, theta_rad
        self.P: F64 = np.zeros((N, N))
        self.P[[X, Y, TH], [X, Y, TH]] = 1e-6
        self.P[B, B], self.P[K, K] = p.bias_sigma0**2, p.turn_scale_sigma0**2
        self.P[HARMONICS, HARMONICS] = p.heading_sigma**2
        self.time_s = time_s
        self.slipping = False
        self.slips = 0
        """Odometry steps in which the wheels slipped."""
        self._gyro: deque[tuple[float, float, float]] = deque(maxlen=GYRO_HISTORY)
        """(time, rate, the rate's integral up to then) of the recent gyro samples."""
        self._gyro_mark = time_s
        """The last odometry step's time: the gyro's turn is counted from here."""
        self._gyro_used = 0.0
        """The gyro integral at the mark (extrapolated when the samples had not reached it yet)."""
        self._origin: float | None = None
        """A set pose's time the gyro samples have not reached yet."""
        self._wheel_heading = theta_rad
        """The wheels' heading: the pose's, plus every wheel turn since it was set."""
        self._disagreement = 0.0
        """Running average of the wheels' disagreement with the gyro, in sigmas."""
        self._rate = self._speed = 0.0
        """The turn rate and the speed of the last step."""
        self._compass_theta: float | None = None
        """The heading at the last compass reading (None: no compass yet)."""

    # -- inputs -------------------------------------------------------------------------------------
    def add_gyro(self, time_s: float, rate_rad_s: float) -> None:
        """One gyro sample (z axis, rad/s, counter-clockwise) taken at `time_s`."""
        if not math.isfinite(rate_rad_s):
            raise CommandRangeError("rate_rad_s", rate_rad_s, "a finite rate in rad/s")
        samples = self._gyro
        if samples and time_s <= samples[-1][0]:
            return  # not after the previous sample: it cannot be placed in time (stamp samples apart)
        if not samples or time_s - samples[-1][0] >= PAUSE_S:
            # The first sample, or after a pause: the rate before it is unknown. It is taken to hold
            # back to the last odometry step when that is recent, so the integral at the mark is the
            # one the filter has used.
            samples.clear()
            lead = time_s - self._gyro_mark
            integral = self._gyro_used + (rate_rad_s * lead if lead < PAUSE_S else 0.0)
        else:
            t1, r1, g1 = samples[-1]
            integral = g1 + 0.5 * (r1 + rate_rad_s) * (time_s - t1)  # the rate is linear between samples
        samples.append((time_s, rate_rad_s, integral))
        while len(samples) > 2 and samples[1][0] <= self._gyro_mark:
            samples.popleft()  # before the last step (one is kept to interpolate from)
        if self._origin is not None and time_s >= self._origin:
            self._gyro_used, self._origin = self._integral(self._origin), None

    def add_odometry(self, time_s: float, distance_m: float, turn_rad: float) -> FusedPose:
        """The wheels' increment since the previous call: distance along the path and heading change."""
        for name, value in (("distance_m", distance_m), ("turn_rad", turn_rad)):
            if not math.isfinite(value):
                raise CommandRangeError(name, value, "a finite number")
        dt = max(0.0, time_s - self.time_s)
        self.time_s = time_s
        samples = self._gyro
        if samples and time_s - samples[-1][0] < PAUSE_S and time_s > self._gyro_mark:
            if self._origin is not None:  # a set pose the samples have not reached: its rate held
                self._gyro_used, self._origin = self._integral(self._origin), None
            # The integral up to now, extrapolated at the last rate if the samples are not in yet:
            # what the later samples show differs from it goes into the next step (by the
            # difference of the integrals), so no turn is lost or counted twice.
            integral = self._integral(time_s)
            gyro_turn, gyro_dt = integral - self._gyro_used, time_s - self._gyro_mark
            self._gyro_used, self._gyro_mark = integral, time_s
            held = max(0.0, time_s - samples[-1][0]), samples[-1][1]
            self._predict(distance_m, gyro_turn, gyro_dt, wheel_turn=turn_rad, dt=dt, held=held)
        else:
            if time_s > self._gyro_mark:  # the wheels have this interval: the gyro's turn counts after it
                if samples:
                    self._gyro_used = self._integral(time_s)
                self._gyro_mark = time_s
            self._predict_wheels_only(distance_m, turn_rad, dt)
        return self.pose

    def add_heading(self, time_s: float, heading_rad: float, sigma_rad: float | None = None) -> None:
        """An absolute heading (magnetometer), in its own frame: the offset to ours is estimated.
        `sigma_rad` replaces the sample-to-sample noise (`heading_noise`)."""
        if not math.isfinite(heading_rad):
            raise CommandRangeError("heading_rad", heading_rad, "a finite angle in rad")
        p = self.params
        theta, dtheta_db = self._heading_at(time_s)
        basis, slope = _harmonics(theta)
        harmonic = float(self.x[HARMONICS] @ basis)
        h = np.zeros(N)
        h[TH] = 1.0 + float(self.x[HARMONICS] @ slope)  # the harmonics turn with the heading
        h[B] = h[TH] * dtheta_db
        h[PSI] = h[C] = 1.0
        h[HARMONICS] = basis
        if self._compass_theta is None:  # the first: the offset is anything, the residual one draw
            self.x[PSI], self.x[C] = _wrap(heading_rad - theta - harmonic), 0.0
            self.P[[PSI, C], :] = self.P[:, [PSI, C]] = 0.0
            self.P[PSI, PSI], self.P[C, C] = UNKNOWN, p.heading_residual_sigma**2
        else:
            # Gauss-Markov in the heading: the residual stays while the robot faces the same way.
            rho = math.exp(-abs(theta - self._compass_theta) / p.heading_correlation_rad)
            self.x[C] *= rho
            self.P[C, :] *= rho
            self.P[:, C] *= rho
            self.P[C, C] += p.heading_residual_sigma**2 * (1.0 - rho * rho)
        self._compass_theta = theta
        r = (sigma_rad or p.heading_noise) ** 2
        self._update(h, _wrap(heading_rad - theta - self.x[PSI] - self.x[C] - harmonic), r)

    def set_pose(self, x_m: float, y_m: float, theta_rad: float, time_s: float | None = None) -> None:
        """Put the pose at (x, y, theta), known again (as at the start); the gyro bias and the wheels'
        turn scale learned so far are kept, and so is a magnetometer's offset to the new heading.
        With `time_s` the pose is the one at that time: the next odometry step starts there (the
        gyro's turn before it is dropped, as a wheel odometry reset drops the counts before it)."""
        for name, value in (("x_m", x_m), ("y_m", y_m), ("theta_rad", theta_rad), ("time_s", time_s or 0.0)):
            if not math.isfinite(value):
                raise CommandRangeError(name, value, "a finite number")
        if time_s is not None:
            self.time_s = self._gyro_mark = time_s
            samples = self._gyro
            self._origin = time_s if samples and time_s > samples[-1][0] else None
            self._gyro_used = self._integral(time_s) if samples else 0.0
        turn = theta_rad - self.x[TH]
        self.x[X], self.x[Y], self.x[TH], self.x[E] = x_m, y_m, theta_rad, 0.0
        self.x[PSI] = _wrap(self.x[PSI] - turn)
        if self._compass_theta is not None:
            self._compass_theta += turn
        # The compass error is the same where the robot faces the same way: its harmonics, in the
        # new heading, turn by the turn (twice it for the second).
        T = np.eye(N)
        for i, n in ((HARMONICS[0], 1), (HARMONICS[2], 2)):
            c, s = math.cos(n * turn), math.sin(n * turn)
            T[i : i + 2, i : i + 2] = ((c, -s), (s, c))
        self.x, self.P = T @ self.x, T @ self.P @ T.T
        self._wheel_heading, self._disagreement = theta_rad, 0.0
        self.P[[X, Y, TH, E], :] = self.P[:, [X, Y, TH, E]] = 0.0
        self.P[X, X] = self.P[Y, Y] = self.P[TH, TH] = 1e-6

    # -- the gyro's integral ------------------------------------------------------------------------
    def _integral(self, t: float) -> float:
        """The gyro's integral at `t`: between samples with the rate linear, beyond the newest at its rate."""
        samples = self._gyro
        t1, r1, g1 = samples[-1]
        if t >= t1 or len(samples) == 1:
            return g1 + r1 * (t - t1)
        i = bisect.bisect_right(samples, t, key=lambda s: s[0])
        if i == 0:
            t0, r0, g0 = samples[0]
            return g0 + r0 * (t - t0)
        (ta, ra, ga), (tb, rb, _) = samples[i - 1], samples[i]
        u = t - ta
        return ga + ra * u + 0.5 * (rb - ra) * u * u / (tb - ta)

    def _heading_at(self, t: float) -> tuple[float, float]:
        """The heading at `t` (the last step's, turned by the gyro since) and its derivative by the bias."""
        if self._gyro and abs(t - self._gyro_mark) < PAUSE_S:
            since = t - self._gyro_mark
            return self.x[TH] + self._integral(t) - self._gyro_used - self.x[B] * since, -since
        return float(self.x[TH]), 0.0

    # -- the filter ---------------------------------------------------------------------------------
    def _wheel_noise(self, ds: float, wheel_turn: float, rate: float, dt: float) -> tuple[float, float]:
        """Variances a step adds to the wheels' heading error and to its distance."""
        p = self.params
        speed = ds / dt if dt > 0 else self._speed
        turn_change, speed_change = abs(rate - self._rate), abs(speed - self._speed)
        self._rate, self._speed = rate, speed
        q_turn = p.wheel_turn_noise**2 * abs(wheel_turn) + p.wheel_turn_per_m**2 * abs(ds)
        q_turn += (p.turn_transient_s * turn_change) ** 2
        return q_turn, (p.distance_noise * ds) ** 2 + (p.distance_transient_s * speed_change) ** 2

    def _predict(
        self,
        ds: float,
        gyro_turn: float,
        gyro_dt: float,
        *,
        wheel_turn: float,
        dt: float,
        held: tuple[float, float] = (0.0, 0.0),
    ) -> None:
        """`held`: how long before the step's end the gyro samples end, and the rate held since."""
        p = self.params
        k = self.x[K]
        turn = gyro_turn - self.x[B] * gyro_dt
        rate = gyro_turn / gyro_dt if gyro_dt > 0 else 0.0
        turn_jac, e_jac = np.zeros(N), np.zeros(N)
        turn_jac[B] = -gyro_dt
        e_jac[K], e_jac[B] = turn, -k * gyro_dt  # the wheels over-read the true turn by k
        q_e, q_ds = self._wheel_noise(ds, wheel_turn, rate, gyro_dt)
        c, s = self._move(
            ds, turn, turn_jac, q_turn=p.gyro_arw**2 * gyro_dt, q_ds=q_ds, dt=dt, e_step=k * turn, e_jac=e_jac, q_e=q_e
        )
        self._wheel_heading += wheel_turn
        h = np.zeros(N)
        h[TH] = h[E] = 1.0
        innovation = self._wheel_heading - self.x[TH] - self.x[E]
        # A count on either wheel; the clocks' offset; and the held rate's error until the samples
        # come (the wheels' rate tells how far the rate has moved). None of it adds up.
        wheel_rate = wheel_turn / gyro_dt if gyro_dt > 0 else 0.0
        r = p.wheel_heading_resolution**2 / 6 + (rate * p.sync_s) ** 2 + ((wheel_rate - held[1]) * held[0]) ** 2
        # Slip shows as one step far off (the gate), or as the wheels drifting from the gyro step after
        # step by less than the gate each (a tyre spinning through a whole turn): their average
        # disagreement, in sigmas, is then further from zero than white noise would leave it.
        z = innovation / math.sqrt(float(h @ self.P @ h) + r)
        self._disagreement += DISAGREEMENT_WEIGHT * (z - self._disagreement)
        drifting = self._disagreement**2 * (2 - DISAGREEMENT_WEIGHT) / DISAGREEMENT_WEIGHT > p.drift_gate
        self.slipping = z * z > p.gate or drifting
        if self.slipping:
            # The wheels slipped: their heading no longer tells where the gyro's is. e forgets what it
            # was (the wheels' heading counts again from here, and neither the bias nor the scale
            # learns from the slip), and the step's distance counts less.
            self.slips += 1
            self.P[E, :] = self.P[:, E] = 0.0
            self.P[E, E] = UNKNOWN
            u = np.array([c, s])
            self.P[X : Y + 1, X : Y + 1] += p.slip_distance_noise**2 * ds * ds * np.outer(u, u)
            self.P[D, D] = max(self.P[D, D], p.slip_distance_noise**2)
        self._update(h, innovation, r)

    def _predict_wheels_only(self, ds: float, wheel_turn: float, dt: float) -> None:
        # No gyro: the heading turns by the wheels' turn less their learnt scale error, and the
        # wheels' heading error is what that correction leaves (theta + e stays the wheels' heading).
        scale = 1.0 + self.x[K]
        turn = wheel_turn / scale
        turn_jac, e_jac = np.zeros(N), np.zeros(N)
        turn_jac[K], e_jac[K] = -wheel_turn / scale**2, wheel_turn / scale**2
        self.slipping = False
        q_turn, q_ds = self._wheel_noise(ds, wheel_turn, wheel_turn / dt if dt > 0 else self._rate, dt)
        self._move(
            ds,
            turn,
            turn_jac,
            q_turn=q_turn,
            q_ds=q_ds,
            dt=dt,
            e_step=wheel_turn - turn,
            e_jac=e_jac,
            q_e=0.0,
            e_turn_noise=-1.0,
        )
        self._wheel_heading += wheel_turn

    def _move(
        self,
        ds: float,
        turn: float,
        turn_jac: F64,
        *,
        q_turn: float,
        q_ds: float,
        dt: float,
        e_step: float,
        e_jac: F64,
        q_e: float,
        e_turn_noise: float = 0.0,
    ) -> tuple[float, float]:
        """Move along the arc; `turn_jac` and `e_jac`: the turn's and e's change by the state."""
        p = self.params
        th = self.x[TH]
        mid = th + turn / 2
        c, s = math.cos(mid), math.sin(mid)
        half = turn / 2
        # The exact arc, as odometry.py; d: the wheels' distance over-read while they slip.
        chord = ds * (1.0 - self.x[D]) * (math.sin(half) / half if abs(half) > 1e-6 else 1.0)
        self.x[X] += chord * c
        self.x[Y] += chord * s
        self.x[TH] = th + turn
        self.x[E] += e_step
        fade = math.exp(-dt / p.slip_time_s)
        self.x[D] *= fade
        mid_jac = turn_jac / 2
        mid_jac[TH] += 1.0
        F = np.eye(N)
        F[X] += -ds * s * mid_jac
        F[Y] += ds * c * mid_jac
        F[X, D], F[Y, D] = -ds * c, -ds * s
        F[TH] += turn_jac
        F[E] += e_jac
        F[D, D] = fade
        G = np.zeros((N, 3))  # noise inputs: distance, turn, the wheels' heading
        G[X, 0], G[Y, 0] = c, s
        G[X, 1], G[Y, 1] = -ds * s / 2, ds * c / 2
        G[TH, 1], G[E, 1] = 1.0, e_turn_noise
        G[E, 2] = 1.0
        Q = G @ np.diag([q_ds, q_turn, q_e]) @ G.T
        Q[B, B] += p.bias_walk**2 * dt
        Q[K, K] += p.turn_scale_walk**2 * dt
        self.P = F @ self.P @ F.T + Q
        return c, s

    def _update(self, h: F64, innovation: float, r: float) -> None:
        Ph = self.P @ h
        s = float(h @ Ph) + r
        k = Ph / s
        self.x = self.x + k * innovation
        # Joseph form, (I - k h) P (I - k h)' + r k k': keeps P symmetric and positive with the tiny
        # noises of a standing robot. In outer products, as the measurement is one number (the
        # compass comes 200 times a second).
        a = self.P - k[:, None] * Ph
        self.P = a - (a @ h)[:, None] * k + r * k[:, None] * k

    # -- output -------------------------------------------------------------------------------------
    @property
    def pose(self) -> FusedPose:
        return FusedPose(
            self.time_s,
            float(self.x[X]),
            float(self.x[Y]),
            float(self.x[TH]),
            float(self.x[B]),
            float(self.x[K]),
            self.P[:3, :3].copy(),
            self.slipping,
        )


class OdometryIncrements:
    """Successive odometry poses (e.g. `robot.odometry.pose` per FEEDBACK) as (distance, turn) steps."""

    def __init__(self) -> None:
        self._last: tuple[float, float, float] | None = None

    def step(self, x_m: float, y_m: float, theta_rad: float) -> tuple[float, float]:
        """Distance along the arc (signed: negative when reversing) and heading change since the last pose."""
        last = self._last
        self._last = (x_m, y_m, theta_rad)
        if last is None:
            return 0.0, 0.0
        dx, dy, turn = x_m - last[0], y_m - last[1], theta_rad - last[2]
        mid = last[2] + turn / 2
        chord = dx * math.cos(mid) + dy * math.sin(mid)
        half = turn / 2
        # The odometry integrates exact arcs: the arc is the chord over sinc(half the turn).
        return chord / (math.sin(half) / half if abs(half) > 1e-6 else 1.0), turn


def _harmonics(theta: float) -> tuple[F64, F64]:
    """The compass error's basis at this heading (cos, sin of it and of twice it) and its slope."""
    c1, s1, c2, s2 = math.cos(theta), math.sin(theta), math.cos(2 * theta), math.sin(2 * theta)
    return np.array([c1, s1, c2, s2]), np.array([-s1, c1, -2 * s2, 2 * c2])


def _wrap(a: float) -> float:
    return math.remainder(a, 2 * math.pi)
