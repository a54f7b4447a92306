"""A spinning 2D triangulation lidar: rotor, sampling, ray casting and the measurement model.

Samples are taken every 1 / sample_rate_hz seconds while the rotor turns at scan_hz (with a slow
speed wander of +-1 %, as a motor under a speed loop has), so a revolution's samples are spread
over its whole period: each is cast from where the robot was at that sample's instant (a scan is not
a snapshot). Per sample:

* range: the first surface along the beam, plus Gaussian noise of the datasheet's sigma
  (`LidarSpec.range_sigma`), quantised later by the wire format;
* no return (range 0 on the wire) beyond range_max or closer than range_min, on glancing surfaces
  (probability rising from 0 at 65 degrees incidence to 1 at 85 degrees), on dark surfaces far
  away, and at random 0.3 % of the time;
* quality: the return strength, from the surface's reflectivity, incidence and distance (0..63).

Angles are the device's: degrees from the sensor's front, clockwise for both reference lidars.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from emulator.world.raycast import nearest
from emulator.world.scene import Scene
from protocol.sensors import LidarSpec, Mount

F64 = NDArray[np.float64]
PoseAt = Callable[[NDArray[np.int64]], tuple[F64, F64, F64]]
"""World pose (x, y, heading arrays) of the robot's pose point at the given virtual times (us)."""

_COS_GLANCE_START = math.cos(math.radians(65))
_COS_GLANCE_END = math.cos(math.radians(85))
RANDOM_DROPOUT = 0.003


@dataclass(frozen=True, slots=True)
class LidarSamples:
    """One batch of samples, in the device's terms (what its wire format encodes)."""

    time_us: NDArray[np.int64]
    angle_deg: F64
    """Rotor angle of each sample, device convention, 0..360."""
    range_m: F64
    """Measured range; 0 where there was no return."""
    quality: NDArray[np.int64]
    """0..63 (0 with no return)."""
    start: NDArray[np.bool_]
    """True on the first sample of each revolution."""
    true_range_m: F64
    """Noise-free range to the surface (inf: nothing there), for ground truth."""

    def __len__(self) -> int:
        return int(self.time_us.shape[0])


class LidarModel:
    def __init__(
        self,
        spec: LidarSpec,
        mount: Mount,
        rng: np.random.Generator | None,
        *,
        scan_hz: float | None = None,
        beam_offset: Callable[[F64], F64] | None = None,
    ) -> None:
        self.spec = spec
        self.mount = mount
        self.rng = rng if rng is not None else np.random.default_rng(0)
        """The noise stream (the device gives the model its own seeded one)."""
        self.scan_hz = scan_hz or spec.scan_hz
        self.sample_us = round(1e6 / spec.sample_rate_hz)
        self.rotor_deg = 0.0
        self.next_sample_us: int | None = None
        self._wander = 0.0
        self.beam_offset = beam_offset
        """Extra bearing (deg, device convention) of the beam as a function of range (mm): the
        triangulation geometry a YDLidar's driver corrects for. None: the beam is the rotor angle."""

    def set_scan_hz(self, hz: float) -> None:
        self.scan_hz = min(self.spec.scan_hz_max, max(self.spec.scan_hz_min, hz))

    def start(self, now_us: int) -> None:
        self.next_sample_us = now_us

    def stop(self) -> None:
        self.next_sample_us = None

    def sample(self, scene: Scene, until_us: int, pose_at: PoseAt) -> LidarSamples | None:
        """Every sample due before `until_us`, or None when not spinning or none is due."""
        if self.next_sample_us is None or self.next_sample_us >= until_us:
            return None
        first = self.next_sample_us
        n = (until_us - first + self.sample_us - 1) // self.sample_us
        times = first + self.sample_us * np.arange(n, dtype=np.int64)
        self.next_sample_us = first + n * self.sample_us
        # The rotor: speed wanders slowly (a random walk held to +-1 %).
        self._wander = float(np.clip(self._wander + self.rng.normal(0, 0.001), -0.01, 0.01))
        step = 360.0 * self.scan_hz * (1 + self._wander) * self.sample_us / 1e6
        unwrapped = self.rotor_deg + step * np.arange(1, n + 1)
        angles = np.mod(unwrapped, 360.0)
        previous = np.concatenate([[self.rotor_deg], unwrapped[:-1]])
        start = np.floor(unwrapped / 360.0) > np.floor(previous / 360.0)
        self.rotor_deg = float(angles[-1])
        true_range, cos, refl = self._cast(scene, times, angles, pose_at)
        return self._measure(times, angles, start, t=true_range, cos=cos, refl=refl)

    def _cast(self, scene: Scene, times: NDArray[np.int64], angles: F64, pose_at: PoseAt) -> tuple[F64, F64, F64]:
        x, y, th = pose_at(times)
        m = self.mount
        c, s = np.cos(th), np.sin(th)
        origins = np.column_stack([x + c * m.x_m - s * m.y_m, y + s * m.x_m + c * m.y_m])
        sign = -1.0 if self.spec.clockwise else 1.0
        base = th + m.yaw_rad

        def shoot(device_deg: F64) -> tuple[F64, NDArray[np.int64], F64]:
            bearing = base + sign * np.radians(device_deg)
            return nearest(scene, origins, np.column_stack([np.cos(bearing), np.sin(bearing)]))

        if self.beam_offset is None:
            t, shape, cos = shoot(angles)
        else:
            t, _, _ = shoot(angles + self.beam_offset(np.full(angles.shape, 1000.0)))
            t, shape, cos = shoot(angles + self.beam_offset(np.where(np.isfinite(t), t * 1000, 1000.0)))
        # Only hits index the scene's shapes (an empty world has none: nothing to gather from).
        hit = shape >= 0
        refl = np.zeros(t.shape)
        refl[hit] = scene.reflectivity[shape[hit]]
        return t, cos, refl

    def _measure(
        self, times: NDArray[np.int64], angles: F64, start: NDArray[np.bool_], *, t: F64, cos: F64, refl: F64
    ) -> LidarSamples:
        spec = self.spec
        rng = self.rng
        n = t.shape[0]
        finite = np.isfinite(t)
        tt = np.where(finite, t, 0.0)
        sigma = np.maximum(spec.range_sigma_m, spec.range_sigma_fraction * tt)
        measured = tt + rng.normal(0.0, 1.0, n) * sigma
        glance = np.clip((_COS_GLANCE_START - cos) / (_COS_GLANCE_START - _COS_GLANCE_END), 0.0, 1.0)
        strength = refl * (0.3 + 0.7 * cos) / (1.0 + (tt / 4.0) ** 2)
        dark = (refl < 0.3) & (tt > 0.5 * spec.range_max_m)
        lost = (rng.random(n) < glance) | (rng.random(n) < RANDOM_DROPOUT) | dark
        valid = finite & ~lost & (measured >= spec.range_min_m) & (measured <= spec.range_max_m)
        quality = np.where(valid, np.clip(np.rint(63 * strength), 1, 63), 0).astype(np.int64)
        return LidarSamples(
            time_us=times,
            angle_deg=angles,
            range_m=np.where(valid, measured, 0.0),
            quality=quality,
            start=start,
            true_range_m=t,
        )
