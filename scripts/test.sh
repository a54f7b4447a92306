#!/usr/bin/env bash
# Installs what the tests need and runs the whole suite: generated-code drift, lint, types, native
# C++ tests (plain, sanitizers, avr-g++), pytest, quick benchmark smoke runs and fuzzing
# (scripts/fuzz.sh: each libFuzzer target for FUZZ_SECONDS, default 60).
# Usage: bash scripts/test.sh [extra pytest args]
#
# Everything Python runs in the checkout's own virtual environment (.venv, made by scripts/venv.sh
# with the `dev` extra, and the ROS 2 wheels of `ros2` and `ros2-build` for the bridge's tests):
# the system's Python is never installed into. Debian packages the tests need (the AVR toolchain,
# simavr, the Arduino core, python3-venv; opencv-doc for the street-camera clip the person
# detector's tests read; chromium and chromium-driver for the web console's browser tests) are
# installed with apt-get when missing (sudo when not root).
set -euo pipefail
cd "$(dirname "$0")/.."

source scripts/debian-packages.sh
install_debian_packages g++ make gcc-avr avr-libc binutils-avr arduino-core-avr simavr libsimavr-dev libelf-dev \
    clang-14 libfuzzer-14-dev libclang-rt-14-dev llvm-14 opencv-doc chromium chromium-driver

# shellcheck source=scripts/venv.sh
source scripts/venv.sh dev,ros2,ros2-build
export PATH="$VENV/bin:$PATH"

# The ROS 2 bridge's tests: cmake and tf2_msgs (built into build/ros2); they must not be skipped.
bash scripts/test_ros2_setup.sh
export ROVERLINK_REQUIRE_ROS2=1

# The web console's tests drive a real browser (Debian's chromium): they must not be skipped either.
export ROVERLINK_REQUIRE_BROWSER=1

echo "== generated files match the spec"
python -m protocol check

echo "== ruff"
ruff check .
ruff format --check .

echo "== mypy --strict"
mypy --strict protocol host_sdk emulator roverlink

echo "== pytest (hypothesis profile: ${HYPOTHESIS_PROFILE:=ci})"
export HYPOTHESIS_PROFILE
python -m pytest "$@"

echo "== codec benchmark (smoke run; full run: .venv/bin/python benchmarks/codec.py)"
python benchmarks/codec.py --quick --require-roverlink

echo "== host receive-path benchmark (smoke run; full run: .venv/bin/python benchmarks/host.py)"
python benchmarks/host.py --quick --rates 100

echo "== console benchmark (smoke run; full run: .venv/bin/python benchmarks/console.py)"
python benchmarks/console.py --seconds 2

echo "== fuzzing (tests/firmware/fuzz: ${FUZZ_SECONDS:=60} s per target; SECURITY.md)"
bash scripts/fuzz.sh --seconds "$FUZZ_SECONDS"
