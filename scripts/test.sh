#!/usr/bin/env bash
# Installs what the tests need and runs the whole suite: generated-code drift, lint, types, native
# C++ tests (plain, sanitizers, avr-g++), pytest, and a quick benchmark smoke run.
# Usage: bash scripts/test.sh [extra pytest args]
#
# Everything Python runs in the checkout's own virtual environment (.venv, made by scripts/venv.sh
# with the `dev` extra): the system's Python is never installed into. Debian packages the tests
# need (the AVR toolchain, simavr, the Arduino core, python3-venv) are installed with apt-get when
# missing (sudo when not root).
set -euo pipefail
cd "$(dirname "$0")/.."

DEBIAN_PACKAGES=(g++ make gcc-avr avr-libc binutils-avr arduino-core-avr simavr libsimavr-dev libelf-dev)

missing=()
for pkg in "${DEBIAN_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
if ((${#missing[@]})); then
    echo "== installing Debian packages: ${missing[*]}"
    if [[ $(id -u) -eq 0 ]]; then sudo=(); else sudo=(sudo); fi
    "${sudo[@]}" apt-get update -qq
    DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq "${missing[@]}" >/dev/null
fi

# shellcheck source=scripts/venv.sh
source scripts/venv.sh dev
export PATH="$VENV/bin:$PATH"

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
