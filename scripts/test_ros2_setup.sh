#!/usr/bin/env bash
# What the ROS 2 bridge's tests (tests/roverlink/ros2) need, in the checkout's .venv (scripts/venv.sh): the
# ROS 2 Jazzy wheels from PyPI (the `ros2` extra) and the rosidl generator wheels (`ros2-build`),
# cmake and a C/C++ compiler (Debian), and tf2_msgs built from its definition into build/ros2
# (skipped when nothing changed). scripts/test.sh runs it before pytest and exports
# ROVERLINK_REQUIRE_ROS2=1, so the ROS tests fail rather than skip if it was left out. Alone:
#
#     bash scripts/test_ros2_setup.sh && ROVERLINK_REQUIRE_ROS2=1 .venv/bin/python -m pytest tests/roverlink/ros2
set -euo pipefail
cd "$(dirname "$0")/.."

# shellcheck source=scripts/debian-packages.sh
source scripts/debian-packages.sh
install_debian_packages cmake g++ make

# shellcheck source=scripts/venv.sh
source scripts/venv.sh dev,ros2,ros2-build

echo "== building tf2_msgs into build/ros2"
"$VENV/bin/python" -m roverlink.ros2.interfaces --prefix build/ros2
