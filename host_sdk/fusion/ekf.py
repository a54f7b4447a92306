"""Wheel odometry + IMU fusion: an extended Kalman filter over the planar pose and the gyro's bias.

    ekf = PoseEkf()
    ekf.add_gyro(t, sample.gyro[2])              # every IMU sample (rad/s about z)
    ekf.add_odometry(t, ds_m, dtheta_rad)        # every wheel odometry increment (robot.odometry)
    ekf.add_heading(t, compass_heading(mag))     # optional: a magnetometer heading
    ekf.pose                                     # FusedPose: x, y, theta, gyro bias, covariance, slip

State: x, y, theta (the odometry frame), the gyro's z bias b, the scale error k of the wheels' turn
(a track width or steering calibration a few per cent off makes every turn read long or short), and
psi, the offset between the odometry frame and the magnetometer's frame (estimated once a heading
arrives).

- **Prediction**, at each odometry increment: the heading turns by the gyro's integral over the
  interval less the bias (a gyro does not slip); the position moves the wheels' distance along the
  mid-interval heading. Gyro noise (angle random walk), the bias random walk and the wheels'
  distance noise feed the covariance.
- **The wheels' own turn as a measurement**: dtheta_wheels should equal (1 + k) times the gyro's
  turn less b * dt. Its noise grows with the size of the turn and is tiny when the wheels say the
  robot did not turn, so standing still or driving straight pins the bias down (a zero-velocity
  update falls out of the model), while turns teach k: a systematic wheel error is not mistaken
  for gyro bias. When the two disagree beyond a chi-square
  gate (99 %), the wheels slipped: the measurement is dropped, the step is flagged, and the wheels'
  distance counts for less.
- **Magnetometer heading** (optional): heading = theta + psi with the compass's noise; it bounds the
  drift left in the bias estimate over long runs. A compass near motors is easily off by degrees
  until calibrated, so its noise is set accordingly.

Without gyro samples in an interval the filter falls back to the wheels' turn (pure odometry).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from host_sdk.errors import CommandRangeError

F64 = NDArray[np.float64]
X, Y, TH, B, K, PSI = range(6)
N = 6
CHI2_1DOF_99 = 6.635


@dataclass(frozen=True, slots=True)
class EkfParams:
    gyro_arw: float = math.radians(0.005)
    """Gyro angle random walk, rad/sqrt(s) (white rate noise density)."""
    bias_walk: float = math.radians(0.01)
    """Gyro bias random walk, rad/s per sqrt(s)."""
    bias_sigma0: float = math.radians(0.3)
    """Initial bias uncertainty, rad/s."""
    distance_noise: float = 0.02
    """Wheel distance error, as a fraction of the distance."""
    slip_distance_noise: float = 0.3
    """... for a step in which the wheels slipped."""
    wheel_turn_noise: float = 0.03
    """Wheel turn error as a fraction of the turn, beyond the scale error the filter learns."""
    turn_scale_sigma0: float = 0.1
    """Initial uncertainty of the wheels' turn scale (track width or steering calibration), fraction."""
    turn_scale_walk: float = 1e-4
    """How fast that scale may change (tyre wear, load), fraction per sqrt(s)."""
    wheel_turn_per_m: float = 0.03
    """Wheel turn error per metre travelled (encoder quantisation, uneven wheels, floor), rad/m."""
    wheel_turn_floor: float = 2e-5
    """Wheel turn noise of a robot standing still (the gyro's own noise over a step), rad."""
    sync_s: float = 0.005
    """Timing mismatch between the wheel and gyro intervals (turn error = rate * sync)."""
    heading_sigma: float = math.radians(5.0)
    """Magnetometer heading noise (hard and soft iron, tilt), rad."""
    gate: float = CHI2_1DOF_99


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
    def __init__(self, params: EkfParams | None = None, *, x_m: float = 0.0, y_m: float = 0.0,
                 theta_rad: float = 0.0, time_s: float = 0.0) -> None:  # fmt: skip
        self.params = p = params or EkfParams()
        self.x: F64 = np.array([x_m, y_m, theta_rad, 0.0, 0.0, 0.0])
        self.P: F64 = np.diag([1e-6, 1e-6, 1e-6, p.bias_sigma0**2, p.turn_scale_sigma0**2, 0.0])
        self.time_s = time_s
        self.slipping = False
        self.slips = 0
        """Odometry steps rejected as wheel slip."""
        self._gyro_turn = 0.0
        """Gyro integral from the last odometry step (`_gyro_mark`) to the last sample."""
        self._gyro_mark = time_s
        self._gyro_last: float | None = None
        self._gyro_rate = 0.0
        self._psi_known = False

    # -- inputs -------------------------------------------------------------------------------------
    def add_gyro(self, time_s: float, rate_rad_s: float) -> None:
        """One gyro sample (z axis, rad/s, counter-clockwise) taken at `time_s`."""
        if not math.isfinite(rate_rad_s):
            raise CommandRangeError("rate_rad_s", rate_rad_s, "a finite rate in rad/s")
        last, mark = self._gyro_last, self._gyro_mark
        if last is not None and time_s <= last:
            return  # not after the previous sample: it cannot be placed in time (stamp samples apart)
        if last is None or time_s - last >= 0.5:  # the first sample, or after a pause in the stream
            if 0 < time_s - mark < 0.5:
                self._gyro_turn += rate_rad_s * (time_s - mark)
        elif time_s > mark:
            # The rate is linear between samples; only the part after the last odometry step counts
            # (the part before it was extrapolated into that step).
            a = max(mark, last)
            ra = self._gyro_rate + (rate_rad_s - self._gyro_rate) * (a - last) / (time_s - last)
            self._gyro_turn += 0.5 * (ra + rate_rad_s) * (time_s - a)
        self._gyro_last = time_s
        self._gyro_rate = rate_rad_s

    def add_odometry(self, time_s: float, distance_m: float, turn_rad: float) -> FusedPose:
        """The wheels' increment since the previous call: distance along the path and heading change."""
        for name, value in (("distance_m", distance_m), ("turn_rad", turn_rad)):
            if not math.isfinite(value):
                raise CommandRangeError(name, value, "a finite number")
        dt = max(0.0, time_s - self.time_s)
        self.time_s = time_s
        last = self._gyro_last
        if last is not None and time_s - last < 0.5 and time_s > self._gyro_mark:
            gyro_dt = time_s - self._gyro_mark
            # Samples are integrated up to `last`: take back what lies beyond now (it belongs to the
            # next step), or hold the last rate up to now, from where the integral ends (the last
            # sample, or the previous step if that already held it past the last sample).
            if last > time_s:
                excess = self._gyro_rate * (last - time_s)
                gyro_turn, self._gyro_turn = self._gyro_turn - excess, excess
            else:
                gyro_turn = self._gyro_turn + self._gyro_rate * (time_s - max(last, self._gyro_mark))
                self._gyro_turn = 0.0
            self._gyro_mark = time_s
            self._predict(distance_m, gyro_turn, gyro_dt, wheel_turn=turn_rad, dt=dt)
        else:
            self._gyro_turn = 0.0
            self._gyro_mark = time_s
            self._predict_wheels_only(distance_m, turn_rad, dt)
        return self.pose

    def add_heading(self, time_s: float, heading_rad: float, sigma_rad: float | None = None) -> None:
        """An absolute heading (magnetometer), in its own frame: the offset to ours is estimated."""
        if not math.isfinite(heading_rad):
            raise CommandRangeError("heading_rad", heading_rad, "a finite angle in rad")
        r = (sigma_rad or self.params.heading_sigma) ** 2
        if not self._psi_known:
            self.x[PSI] = _wrap(heading_rad - self.x[TH])
            self.P[PSI, :] = self.P[:, PSI] = 0.0
            self.P[PSI, PSI] = r + self.P[TH, TH]
            self.P[PSI, TH] = self.P[TH, PSI] = -self.P[TH, TH]
            self._psi_known = True
            return
        h = np.zeros(N)
        h[TH] = h[PSI] = 1.0
        self._update(h, _wrap(heading_rad - self.x[TH] - self.x[PSI]), r, gate=False)

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
            self._gyro_turn = 0.0
        turn = theta_rad - self.x[TH]
        self.x[X], self.x[Y], self.x[TH] = x_m, y_m, theta_rad
        self.x[PSI] = _wrap(self.x[PSI] - turn)
        self.P[:3, :] = self.P[:, :3] = 0.0
        self.P[X, X] = self.P[Y, Y] = self.P[TH, TH] = 1e-6

    # -- the filter ---------------------------------------------------------------------------------
    def _predict(self, ds: float, gyro_turn: float, gyro_dt: float, *, wheel_turn: float, dt: float) -> None:
        p = self.params
        # The wheels' turn against the gyro's first: a bias (and scale) measurement, or a slip.
        true_turn = gyro_turn - self.x[B] * gyro_dt
        scale = 1.0 + self.x[K]
        h = np.zeros(N)
        h[B] = -scale * gyro_dt
        h[K] = true_turn
        expected = scale * true_turn
        rate = abs(gyro_turn / gyro_dt) if gyro_dt > 0 else 0.0
        sigma = p.wheel_turn_floor + p.wheel_turn_noise * abs(wheel_turn) + p.wheel_turn_per_m * abs(ds)
        sigma += rate * p.sync_s
        # The innovation is judged against the state before this step's turn: only b enters it.
        accepted = self._update(h, wheel_turn - expected, sigma * sigma, gate=True)
        self.slipping = not accepted
        if not accepted:
            self.slips += 1
        turn = gyro_turn - self.x[B] * gyro_dt
        frac = p.slip_distance_noise if self.slipping else p.distance_noise
        self._move(ds, turn, q_turn=p.gyro_arw**2 * gyro_dt, q_ds=(frac * ds) ** 2, dt=dt, d_turn_d_b=-gyro_dt)

    def _predict_wheels_only(self, ds: float, turn: float, dt: float) -> None:
        p = self.params
        sigma = p.wheel_turn_floor + p.wheel_turn_noise * abs(turn) + p.wheel_turn_per_m * abs(ds)
        self.slipping = False
        self._move(ds, turn, q_turn=sigma * sigma, q_ds=(p.distance_noise * ds) ** 2, dt=dt, d_turn_d_b=0.0)

    def _move(self, ds: float, turn: float, *, q_turn: float, q_ds: float, dt: float, d_turn_d_b: float) -> None:
        p = self.params
        th = self.x[TH]
        mid = th + turn / 2
        c, s = math.cos(mid), math.sin(mid)
        half = turn / 2
        chord = ds * (math.sin(half) / half if abs(half) > 1e-6 else 1.0)  # the exact arc, as odometry.py
        self.x[X] += chord * c
        self.x[Y] += chord * s
        self.x[TH] = th + turn
        F = np.eye(N)
        F[X, TH], F[Y, TH] = -ds * s, ds * c
        F[X, B], F[Y, B] = -ds * s * d_turn_d_b / 2, ds * c * d_turn_d_b / 2
        F[TH, B] = d_turn_d_b
        G = np.zeros((N, 2))  # noise inputs: distance, turn
        G[X, 0], G[Y, 0] = c, s
        G[X, 1], G[Y, 1] = -ds * s / 2, ds * c / 2
        G[TH, 1] = 1.0
        Q = G @ np.diag([q_ds, q_turn]) @ G.T
        Q[B, B] += p.bias_walk**2 * dt
        Q[K, K] += p.turn_scale_walk**2 * dt
        self.P = F @ self.P @ F.T + Q

    def _update(self, h: F64, innovation: float, r: float, *, gate: bool) -> bool:
        Ph = self.P @ h
        s = float(h @ Ph) + r
        if gate and innovation * innovation / s > self.params.gate:
            return False
        k = Ph / s
        self.x = self.x + k * innovation
        # Joseph form: keeps P symmetric and positive with the tiny noises of a standing robot.
        ikh = np.eye(N) - np.outer(k, h)
        self.P = ikh @ self.P @ ikh.T + r * np.outer(k, k)
        return True

    # -- output -------------------------------------------------------------------------------------
    @property
    def pose(self) -> FusedPose:
        return FusedPose(self.time_s, float(self.x[X]), float(self.x[Y]), float(self.x[TH]), float(self.x[B]),
                         float(self.x[K]), self.P[:3, :3].copy(), self.slipping)  # fmt: skip


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


def _wrap(a: float) -> float:
    return math.remainder(a, 2 * math.pi)
