"""Front-cut lidar revolutions as the drivers deliver them, with one revolution's times late (a
host that stalled before reading it), for the scan-stamp tests of the SDK and the ROS 2 node."""

from __future__ import annotations

import math

import numpy as np

from host_sdk.sensors import LidarScan

RATE = 2000.0
"""Samples per second (an RPLIDAR A1 takes about 2000)."""
REAR, FRONT = math.pi, 0.0
"""Turns of the device where a late stretch can start: the rear cut (one LaserScan's points) or the
front (one of the driver's revolutions)."""


def revolutions(hz: float, count: int, *, late_s: float = 0.0, late: int = 0, start: float = REAR) -> list[LidarScan]:
    """`count` revolutions of a clockwise device turning at `hz` with true times, but for the
    samples of one revolution from turn `start` of revolution `late` on: `late_s` late."""
    n = round(count / hz * RATE)
    t = np.arange(n) / RATE
    turned = 2 * math.pi * hz * t + 0.3  # starts a little past the front
    lo = 2 * math.pi * late + start
    measured = np.where((turned >= lo) & (turned < lo + 2 * math.pi), t + late_s, t)
    rad = np.angle(np.exp(-1j * np.mod(turned, 2 * math.pi)))
    cuts = np.flatnonzero(np.diff(np.floor(turned / (2 * math.pi))) > 0) + 1
    out = []
    for i, (a, b) in enumerate(zip([0, *cuts], [*cuts, n], strict=True)):
        out.append(
            LidarScan(
                "rplidar-a1",
                i,
                rad[a:b],
                np.full(b - a, 2.0),
                np.full(b - a, 10),
                measured[a:b],
                0.15,
                12.0,
                measured_s=measured[a:b],
            )
        )
    return out
