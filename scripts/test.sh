#!/usr/bin/env bash
# Installs what the tests need (Debian and Python packages) and runs the whole suite:
# generated-code drift, lint, types, native C++ tests (plain, sanitizers, avr-g++), pytest,
# and a quick benchmark smoke run. Usage: bash scripts/test.sh [extra pytest args]
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
