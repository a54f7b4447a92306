"""ROS 2 test setup: DDS kept on this host in a per-run domain, tf2_msgs built once and loaded.

The suites that talk to a node need the `ros2` extra (rclpy and the message packages); without
it they are skipped, unless ROVERLINK_REQUIRE_ROS2=1 (exported by scripts/test.sh),
which turns the skip into a failure so a missing install cannot pass unnoticed. The plain-Python
parts of the bridge (parameters, conversions, the driver, diagnostics) are tested either way.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from ros_env import INTERFACES


@pytest.fixture(scope="session")
def tf2_msgs() -> Path:
    """Build tf2_msgs into build/ros2 (once; cached across runs) and load it into this process."""
    from roverlink.ros2.interfaces import InterfaceBuildError, activate, build

    try:
        build(INTERFACES)
    except InterfaceBuildError as exc:
        pytest.fail(
            f"cannot build tf2_msgs for the /tf tests: {exc} (scripts/test_ros2_setup.sh installs what it needs)"
        )
    activate(INTERFACES)  # and into os.environ, which the bridge processes inherit
    return INTERFACES


@pytest.fixture(scope="session")
def ros(tf2_msgs: Path) -> Iterator[None]:
    """rclpy initialised once for the session (after tf2_msgs is loadable, for the bridge processes too)."""
    import rclpy

    rclpy.init()
    yield
    rclpy.try_shutdown()
