"""Turns measured by the IMU: the JY901's yaw, its bias handled, for the track width.

The track width comes from an in-place turn: the wheels' count difference says how far odometry
believes the robot turned, and something else must say how far it really did. A person with a
protractor is one; an IMU on the robot is another, and it is already there.

How the turn is read from the module's yaw:

- the yaw is unwrapped sample by sample (a sample every 5 ms; far less than half a turn apart);
- before the turn, over `rest_s` at rest, the yaw's drift rate is measured: in 6-axis mode the
  module integrates its gyro alone and drifts with the gyro's bias; in 9-axis mode the compass
  holds it (the drift is then about zero);
- after the turn the module gets `settle_s` at rest: its 9-axis filter pulls the yaw towards the
  compass with a 2 s time constant, so the yaw read right after stopping still lags;
- turn = mean yaw over `rest_s` after - mean yaw over `rest_s` before - drift x the time between
  the two windows' middles.

In 9-axis mode the result leans on the compass at both ends, so a gyro's scale error cancels; an
uncalibrated compass (hard iron) costs a fraction of a degree, since a full turn ends near the
heading it started at. The gyro's own z rate, less its mean at rest, integrated between the same
two moments, is kept beside it: when the two disagree by more than 2 % the compass is disturbed
(motors, steel) or the gyro's scale is off, and the finding says so.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass

import numpy as np

from host_sdk import Robot
from host_sdk.sensors import ImuSample
from host_sdk.sensors.hub import Sensors
from roverlink.calibration.observer import Observer

REST_S = 1.0
SETTLE_S = 5.0
STILL_RAD_S = math.radians(1.0)
"""At rest: the gyro's z rate stays within this of its median (bias and noise are far smaller)."""
DISAGREE = 0.02


@dataclass(frozen=True, slots=True)
class ImuTurn:
    yaw_rad: float
    """The turn by the yaw, its drift taken out."""
    gyro_rad: float
    """The turn by the gyro's z rate, its bias taken out."""
    drift_rad_s: float
    """The yaw's drift at rest before the turn."""
    bias_rad_s: float
    """The gyro's z rate at rest before the turn."""
    span_s: float
    """Time between the two rest windows' middles (over which the drift was taken out)."""

    @property
    def disagreement(self) -> float:
        """|yaw - gyro| / |yaw|."""
        return abs(self.yaw_rad - self.gyro_rad) / abs(self.yaw_rad) if self.yaw_rad else math.inf


def measure_turn(
    t: np.ndarray, yaw: np.ndarray, gz: np.ndarray, before: tuple[float, float], after: tuple[float, float]
) -> ImuTurn:
    """The turn between two rest windows (see the module docstring). `yaw` is unwrapped; `t` the
    samples' times; `before` and `after` the windows (start, end) on that clock."""
    b = (t >= before[0]) & (t <= before[1])
    a = (t >= after[0]) & (t <= after[1])
    if b.sum() < 3 or a.sum() < 3:
        raise ValueError(f"the IMU sent {int(b.sum())} samples at rest before the turn and {int(a.sum())} after")
    tb, yb = t[b], yaw[b]
    drift = float(np.polyfit(tb - tb.mean(), yb, 1)[0]) if np.ptp(tb) > 0 else 0.0
    mid_b, mid_a = float(tb.mean()), float(t[a].mean())
    yaw_turn = float(yaw[a].mean() - yb.mean()) - drift * (mid_a - mid_b)
    bias = float(gz[b].mean())
    span = (t >= mid_b) & (t <= mid_a)
    n = int(span.sum())
    # Mean sample period over the span: robust to samples read (and stamped) in batches.
    dt = (mid_a - mid_b) / n if n else 0.0
    gyro_turn = float((gz[span] - bias).sum()) * dt
    return ImuTurn(yaw_turn, gyro_turn, drift, bias, mid_a - mid_b)


class YawTrack:
    """The IMU's samples as (time, unwrapped yaw, z rate); thread-safe (a reading thread adds)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._t: list[float] = []
        self._yaw: list[float] = []
        self._gz: list[float] = []
        self._last: float | None = None
        self._unwrapped = 0.0
        """The yaw since the first sample, turns counted."""

    def add(self, sample: ImuSample) -> None:
        if sample.angle is None or sample.gyro is None:
            return
        yaw = sample.angle[2]
        with self._lock:
            step = 0.0 if self._last is None else math.remainder(yaw - self._last, math.tau)
            self._last = yaw
            self._unwrapped += step
            self._t.append(sample.t)
            self._yaw.append(self._unwrapped)
            self._gz.append(sample.gyro[2])

    def drop_before(self, t: float) -> None:
        """Forget the samples older than `t` (keeps a long session's memory bounded)."""
        with self._lock:
            keep = next((i for i, ti in enumerate(self._t) if ti >= t), len(self._t))
            del self._t[:keep], self._yaw[:keep], self._gz[:keep]

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        with self._lock:
            return np.array(self._t), np.array(self._yaw), np.array(self._gz)

    def __len__(self) -> int:
        with self._lock:
            return len(self._t)


class ImuObserver:
    """An Observer that measures rotations with the IMU and asks `base` everything else (the
    wheels' turns, distances: a person, or the emulator's truth)."""

    def __init__(
        self, base: Observer, robot: Robot, sensors: Sensors, *, rest_s: float = REST_S, settle_s: float = SETTLE_S
    ) -> None:
        if sensors.imu is None:
            raise ValueError("sensors: no IMU to measure turns with")
        self.base = base
        self.robot = robot
        self.sensors = sensors
        self.rest_s = rest_s
        self.settle_s = settle_s
        self.track = YawTrack()
        self.last: ImuTurn | None = None
        self._before: tuple[float, float] | None = None
        self._unsubscribe = sensors.on_imu(self.track.add)
        sensors.start()

    def close(self) -> None:
        self._unsubscribe()

    def _wait(self, seconds: float) -> None:
        end = self.robot.now() + seconds
        while (left := end - self.robot.now()) > 0:
            self.robot.sleep(min(0.02, left))
            self.sensors.poll()

    def _still(self, since: float, until: float) -> bool:
        t, _, gz = self.track.arrays()
        window = gz[(t >= since) & (t <= until)]
        if window.size < self.rest_s * 50:  # under a quarter of the module's 200 Hz
            return False
        return bool(np.abs(window - np.median(window)).max() < STILL_RAD_S)

    # -- Observer --------------------------------------------------------------------------------
    def place(self, on_stand: bool) -> None:
        self.base.place(on_stand)

    def mark(self) -> None:
        """The base's mark; and the yaw at rest: the last `rest_s` if the robot stood still, else
        `rest_s` more now."""
        self.base.mark()
        self.sensors.poll()
        now = self.robot.now()
        if not self._still(now - self.rest_s, now):
            self._wait(self.rest_s)
            now = self.robot.now()
        self._before = (now - self.rest_s, now)
        self.track.drop_before(now - 2 * self.rest_s)

    def turned_forward(self, wheel: int) -> bool:
        return self.base.turned_forward(wheel)

    def revolutions(self, wheel: int) -> float:
        return self.base.revolutions(wheel)

    def displacement(self) -> tuple[float, float]:
        return self.base.displacement()

    def rotation_deg(self) -> float:
        """The turn since the mark, by the IMU (after `settle_s + rest_s` at rest)."""
        if self._before is None:
            raise RuntimeError("mark() first")
        self._wait(self.settle_s + self.rest_s)
        now = self.robot.now()
        t, yaw, gz = self.track.arrays()
        self.last = measure_turn(t, yaw, gz, self._before, (now - self.rest_s, now))
        return math.degrees(self.last.yaw_rad)
