#!/usr/bin/env bash
# Installs what the ROS 2 bridge's tests (tests/ros2) need, into the Python on PATH (a venv when
# one is active): the ROS 2 Jazzy wheels from PyPI (the `ros2` extra), the rosidl generator wheels
# (`ros2-build`), cmake and a C/C++ compiler (Debian), then builds tf2_msgs into build/ros2 (cached:
# skipped when nothing changed). Run it before pytest, with ROVERLINK_REQUIRE_ROS2=1 exported so the
# ROS tests fail rather than skip if this step was left out:
#
#     bash scripts/test_ros2_setup.sh && ROVERLINK_REQUIRE_ROS2=1 python3 -m pytest tests/ros2
set -euo pipefail
cd "$(dirname "$0")/.."
PYTHON=${PYTHON:-python3}

bash scripts/ensure_debian_packages.sh cmake g++ make

echo "== installing the ROS 2 wheels (roverlink[ros2,ros2-build])"
"$PYTHON" -m pip install -q --disable-pip-version-check -e ".[ros2,ros2-build]"

echo "== building tf2_msgs into build/ros2"
"$PYTHON" -m roverlink.ros2.interfaces --prefix build/ros2
