#!/usr/bin/env bash
# The tests, in two lanes (docs/testing.md):
#
#   bash scripts/test.sh                 # the full run, what CI runs (.ci/run): installs what the tests need
#   bash scripts/test.sh --quick         # the fast lane: drift check, ruff, mypy and the unit tests (under 3 min)
#   bash scripts/test.sh [--quick] ARGS  # extra arguments go to pytest, e.g. tests/protocol -x
#
# The full run installs the Debian packages the tests need when they are missing (the AVR
# toolchain, simavr, the Arduino core, python3-venv; clang 14 and libFuzzer for the fuzzing;
# opencv-doc for the street-camera clip the person detector's tests read; chromium and
# chromium-driver for the web console's browser tests; Debian's ARM toolchain, Node.js and npm for
# the RP2040 backend (rp2040js from tools/rp2040's lockfile); apt-get, with sudo when not root), makes the
# checkout's virtual environment .venv with the `dev` extra and the ROS 2 wheels (scripts/venv.sh:
# the system's Python is never installed into), builds tf2_msgs for the ROS 2 tests, then checks
# the generated code for drift, runs ruff and mypy --strict, pytest (the C++ native tests, the
# simavr firmware-in-the-loop suites, ROS 2 and the browser included) on every core and then the
# suites that need the whole machine on their own, benchmark smoke runs and 60 s of fuzzing (the
# three targets at once, scripts/fuzz.sh). It prints each stage's time and the total, and warns past 25 minutes.
#
# The fast lane needs only the venv with the `dev` extra (made on its first run): no apt, no ROS 2,
# no compiler, no browser. PYTEST_WORKERS sets the number of pytest processes (default: nproc).
set -euo pipefail
cd "$(dirname "$0")/.."

quick=0
if [[ ${1:-} == --quick ]]; then
    quick=1
    shift
fi
workers=${PYTEST_WORKERS:-$(nproc)}
export HYPOTHESIS_PROFILE=${HYPOTHESIS_PROFILE:-ci}

source scripts/stages.sh
source scripts/debian-packages.sh

# pytest, where a lane that selects nothing (exit 5: e.g. ARGS naming one folder) is not a failure.
pytest_lane() {
    local status=0
    python -m pytest "$@" || status=$?
    if ((status == 5)); then
        echo "(no test of this lane selected)"
        return 0
    fi
    return "$status"
}

checks() {
    stage "generated files match the spec" python -m protocol check
    stage "ruff" bash -c 'ruff check . && ruff format --check .'
    stage "mypy --strict" mypy --strict protocol host_sdk emulator roverlink
}

if ((quick)); then
    # shellcheck source=scripts/venv.sh
    stage "virtual environment (.venv, dev)" source scripts/venv.sh dev
    export PATH="$VENV/bin:$PATH"
    checks
    stage "pytest: the unit tests (-m 'not slow', $workers workers)" \
        pytest_lane -m "not slow" -n "$workers" -q "$@"
    exit 0
fi

# Node.js and npm from Debian unless the machine has them (a nodesource nodejs carries its npm and
# conflicts with Debian's).
node_packages=()
command -v node >/dev/null || node_packages+=(nodejs)
command -v npm >/dev/null || node_packages+=(npm)
stage "Debian packages" install_debian_packages g++ make gcc-avr avr-libc binutils-avr arduino-core-avr simavr \
    libsimavr-dev libelf-dev clang-14 libfuzzer-14-dev libclang-rt-14-dev llvm-14 opencv-doc chromium chromium-driver \
    python3-venv python3-opencv gstreamer1.0-plugins-base gcc-arm-none-eabi libnewlib-arm-none-eabi \
    "${node_packages[@]}"
# shellcheck source=scripts/venv.sh
stage "virtual environment (.venv, dev + ROS 2)" source scripts/venv.sh dev,ros2,ros2-build
export PATH="$VENV/bin:$PATH"

# The ROS 2 bridge's tests: cmake and tf2_msgs (built into build/ros2); they must not be skipped.
stage "ROS 2 test setup (tf2_msgs)" bash scripts/test_ros2_setup.sh
export ROVERLINK_REQUIRE_ROS2=1
# The web console's tests drive a real browser (Debian's chromium): they must not be skipped either.
export ROVERLINK_REQUIRE_BROWSER=1
# The RP2040 backend: rp2040js at the lockfile's version, in tools/rp2040/node_modules.
stage "rp2040js (npm ci)" npm ci --prefix tools/rp2040 --no-audit --no-fund --loglevel=error
export ROVERLINK_REQUIRE_RP2040=1

checks
# Each pytest stage ends with its slowest tests: where the time goes, run after run.
slowest=(--durations=15 --durations-min=5)
stage "pytest on $workers workers (-m 'not serial', hypothesis profile $HYPOTHESIS_PROFILE)" \
    pytest_lane -m "not serial" -n "$workers" --dist loadfile "${slowest[@]}" "$@"
stage "pytest, the suites that need the whole machine (-m serial)" pytest_lane -m serial "${slowest[@]}" "$@"

# The core packages on Python 3.10 and 3.13 (CI sets ROVERLINK_REQUIRE_PYTHONS=1: a missing one fails)
stage "the core packages' unit tests on Python 3.10 and 3.13 (scripts/test_pythons.sh)" bash scripts/test_pythons.sh
stage "the distribution's camera route (scripts/test_system_opencv.sh)" bash scripts/test_system_opencv.sh

stage "codec benchmark (smoke run; full run: .venv/bin/python benchmarks/codec.py)" \
    python benchmarks/codec.py --quick --require-roverlink
stage "host receive-path benchmark (smoke run; full run: .venv/bin/python benchmarks/host.py)" \
    python benchmarks/host.py --quick --rates 100
stage "console benchmark (smoke run; full run: .venv/bin/python benchmarks/console.py)" \
    python benchmarks/console.py --seconds 2
# The node as it runs by default (normal scheduling, realtime_priority 0).
stage "ROS 2 bridge on a loaded host (smoke run; full run: .venv/bin/python benchmarks/ros2.py --loaded)" \
    python benchmarks/ros2.py --loaded --seconds 30 --warn-only
stage "fuzzing (tests/firmware/fuzz: the targets at once for ${FUZZ_SECONDS:=60} s; SECURITY.md)" \
    bash scripts/fuzz.sh --seconds "$FUZZ_SECONDS"
