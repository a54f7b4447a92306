"""ROS 2 test environment: DDS kept on this host in a per-run domain; skip or fail without ROS 2.

Imported by conftest.py before anything imports rclpy (the domain is read when rclpy starts).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from roverlink.ros2 import INSTALL_HINT, missing_modules

ROOT = Path(__file__).resolve().parents[3]
INTERFACES = ROOT / "build" / "ros2"
"""Where tf2_msgs is built for the tests (not committed; rebuilt when its inputs change)."""

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
os.environ.setdefault("ROS_DOMAIN_ID", str(1 + os.getpid() % 100))

MISSING = missing_modules()


def require_ros() -> None:
    """Skip (or, with ROVERLINK_REQUIRE_ROS2=1, fail) a test module that needs ROS 2."""
    if not MISSING:
        return
    reason = f"ROS 2 is not installed ({', '.join(MISSING)} missing): {INSTALL_HINT}; or run scripts/test_ros2_setup.sh"
    if os.environ.get("ROVERLINK_REQUIRE_ROS2") == "1":
        pytest.fail(reason, pytrace=False)
    pytest.skip(reason, allow_module_level=True)
