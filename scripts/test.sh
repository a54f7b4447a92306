#!/usr/bin/env bash
# Installs what the tests need (Debian and Python packages) and runs the whole suite:
# generated-code drift, lint, types, native C++ tests (plain, sanitizers, avr-g++), pytest,
# a quick benchmark smoke run and fuzzing (scripts/fuzz.sh). Usage: bash scripts/test.sh [extra pytest args]
set -euo pipefail
cd "$(dirname "$0")/.."

source scripts/debian-packages.sh
install_debian_packages g++ make gcc-avr avr-libc binutils-avr arduino-core-avr simavr libsimavr-dev libelf-dev \
    clang-14 libfuzzer-14-dev libclang-rt-14-dev llvm-14

echo "== installing Python packages"
python3 -m pip install -q --disable-pip-version-check -e ".[dev]"

echo "== generated files match the spec"
python3 -m protocol check

echo "== ruff"
ruff check .
ruff format --check .

echo "== mypy --strict"
mypy --strict protocol host_sdk emulator roverlink

echo "== pytest (hypothesis profile: ${HYPOTHESIS_PROFILE:=ci})"
export HYPOTHESIS_PROFILE
python3 -m pytest "$@"

echo "== codec benchmark (smoke run; full run: python3 benchmarks/codec.py)"
python3 benchmarks/codec.py --quick --require-roverlink

echo "== fuzzing (tests/fuzz: ${FUZZ_SECONDS:=60} s per target; SECURITY.md)"
bash scripts/fuzz.sh --seconds "$FUZZ_SECONDS"
