"""Expected lidar ranges from the scene: what a noise-free device would report for each point."""

from __future__ import annotations

import math

import numpy as np

from emulator.world.raycast import nearest
from emulator.world.scene import Scene
from host_sdk.sensors import LidarScan
from protocol.sensors import DEVICES, LidarSpec, Mount


def agreement(scan: LidarScan, scene: Scene, pose: tuple[float, float, float], mount: Mount) -> float:
    """Share of the valid points within 4 sigma (plus the wire's 0.25 mm step) of the scene."""
    spec = DEVICES[scan.device]
    assert isinstance(spec, LidarSpec)
    x, y, th = pose
    ox = x + math.cos(th) * mount.x_m - math.sin(th) * mount.y_m
    oy = y + math.sin(th) * mount.x_m + math.cos(th) * mount.y_m
    ok = scan.valid
    bearing = th + mount.yaw_rad + scan.angles_rad[ok]
    dirs = np.column_stack([np.cos(bearing), np.sin(bearing)])
    expected, _, _ = nearest(scene, np.tile([ox, oy], (dirs.shape[0], 1)), dirs)
    sigma = np.maximum(spec.range_sigma_m, spec.range_sigma_fraction * expected)
    close = np.abs(scan.ranges_m[ok] - expected) <= 4 * sigma + 0.0005
    return float(close.mean())
