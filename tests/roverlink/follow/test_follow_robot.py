"""`roverlink follow` on "a robot": the board, lidar and IMU on real ptys and the camera on HTTP, served
in real time by `roverlink emulate`, opened by the same paths a Raspberry Pi's ports would be."""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from emulator.sensors.target import camera_mount, render_target
from emulator.world import load_world
from tests.support.emulate import emulate

WORLD = Path(__file__).resolve().parents[3] / "examples" / "worlds" / "follow_ahead.toml"


@pytest.fixture
def served() -> Iterator[dict[str, str]]:
    args = [
        "--profile",
        "picar",
        "--world",
        str(WORLD),
        "--eeprom",
        "saved",
        "--lidar",
        "ydlidar-f4",
        "--imu",
        "jy901",
        "--camera",
        "--quiet",
        "--seed",
        "1",
    ]
    with emulate(*args, devices=3, clean_exit=True) as served:
        yield {"board": served.url, **{name: words[-1] for name, words in served.devices.items()}}


def test_follow_on_ptys_and_an_http_camera(served: dict[str, str], tmp_path: Path) -> None:
    import cv2

    template = render_target(load_world(WORLD), camera_mount("picar"))  # the user's photo of the target
    image = tmp_path / "target.png"
    cv2.imwrite(str(image), template.image)
    cmd = [
        sys.executable,
        "-m",
        "roverlink",
        "follow",
        "--url",
        served["board"],
        "--profile",
        "picar",
        "--lidar",
        served["lidar"],
        "--imu",
        served["imu"],
        "--camera",
        served["camera"],
        "--template",
        str(image),
        "--target-height",
        f"{template.height_m:.3f}",
        "--duration",
        "6",
        "--json",
        "--quiet",
    ]
    done = subprocess.run(cmd, check=False, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    m = json.loads(done.stdout)
    # It ran for the time asked and then stopped (a step that ends late on a loaded machine adds to it).
    assert 6.0 - 0.05 <= m["duration_s"] < 6.0 + 3.0
    assert not m["ground_truth"] and m["collisions"] is None  # a robot has no truth to count them from
    assert m["collided_with"] is None and m["in_view_fraction"] is None
    assert m["url"] == served["board"] and m["world"] is None
    assert m["first_sight_s"] is not None and m["first_sight_s"] < 2.0
    assert m["tracked_fraction"] > 0.8
    assert m["follow_error_mean_m"] is not None  # from the tracker's and the lidar's gap
