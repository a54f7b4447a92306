#!/usr/bin/env bash
# The unit tests of the core packages on the oldest and the newest Python RoverLink supports, each
# in a virtual environment of its own in the checkout (.venv-py310, .venv-py313): protocol
# (tests/protocol), the SDK's core (tests/host_sdk/test_*.py: Robot, session, transports,
# kinematics, odometry, asyncio, the pytest plugin) and the emulator's core (tests/emulator/test_*.py:
# the plant, the firmware model, the session, faults; its sensor and world models stay on the main
# interpreter with the SDK's sensors), without the modules marked slow (processes, simavr: they test the machine, not the interpreter) and with
# Hypothesis's `interpreters` profile (fewer examples: the main interpreter runs the full count).
# The full suite runs on the main interpreter (scripts/test.sh, which runs this script too).
#
#   bash scripts/test_pythons.sh                 # 3.10 and 3.13
#   bash scripts/test_pythons.sh 3.12 -- -x      # other versions; pytest arguments after --
#
# An interpreter is looked for as pythonX.Y on PATH, then in pyenv's versions. One that is missing
# is skipped with one line, unless ROVERLINK_REQUIRE_PYTHONS=1 (CI), which makes it a failure.
# Each venv gets the package (editable, as scripts/venv.sh installs it) with the `test` and
# `vision` extras, installed again when pyproject.toml is newer than the last install.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT="$PWD"
# shellcheck source=scripts/editable.sh
source scripts/editable.sh
EDITABLE_TAG="$EDITABLE_MODE-$(editable_digest)"

versions=()
while [[ $# -gt 0 && "$1" != "--" ]]; do
    versions+=("$1")
    shift
done
[[ "${1:-}" == "--" ]] && shift
[[ ${#versions[@]} -gt 0 ]] || versions=(3.10 3.13)
CORE_NAMES='tests/protocol tests/host_sdk/test_*.py tests/emulator/test_*.py'
read -r -a CORE_TESTS <<< "$(echo $CORE_NAMES)"
# The oldest Python runs with the oldest numpy RoverLink allows: Ubuntu 22.04's and JetPack 6's
# python3-numpy (1.21.5), which a venv made with --system-site-packages there keeps.
declare -A PINS=([3.10]="numpy==1.21.*")

find_python() {
    local version="$1" candidate root
    # A pyenv shim is on PATH for every version pyenv has, so the candidate must also run.
    if candidate="$(command -v "python$version")" && "$candidate" -c 'import sys' >/dev/null 2>&1; then
        echo "$candidate"
        return 0
    fi
    if root="$(pyenv root 2>/dev/null)" || root="${PYENV_ROOT:-$HOME/.pyenv}"; then
        for candidate in $(ls -d "$root/versions/$version".* 2>/dev/null | sort -V -r); do
            if [[ -x "$candidate/bin/python$version" ]]; then
                echo "$candidate/bin/python$version"
                return 0
            fi
        done
    fi
    return 1
}

run_version() {
    local version="$1" python venv stamp start
    shift
    if ! python="$(find_python "$version")"; then
        if [[ "${ROVERLINK_REQUIRE_PYTHONS:-}" == "1" ]]; then
            echo "== Python $version: not found (on PATH or in pyenv), and ROVERLINK_REQUIRE_PYTHONS=1" >&2
            return 1
        fi
        echo "== Python $version: not found (on PATH or in pyenv), skipped"
        return 0
    fi
    ran+=("$version")
    start=$SECONDS
    venv=".venv-py${version/./}"
    if [[ ! -x "$venv/bin/python" ]] || ! "$venv/bin/python" -m pip --version >/dev/null 2>&1; then
        echo "== creating $venv ($("$python" --version))"
        rm -rf "$venv"
        "$python" -m venv "$venv"
    fi
    local pin="${PINS[$version]:-}"
    stamp="$venv/.installed-$EDITABLE_TAG-test-vision${pin:+-${pin//[^0-9a-z.]/}}"
    if [[ ! -f "$stamp" || pyproject.toml -nt "$stamp" ]]; then
        echo "== installing roverlink[test,vision]${pin:+ with $pin} into $venv"
        rm -f "$venv"/.installed-*
        "$venv/bin/python" -m pip install -q --disable-pip-version-check \
            --config-settings editable_mode="$EDITABLE_MODE" -e ".[test,vision]" ${pin:+"$pin"}
        touch "$stamp"
    fi
    echo "== pytest on $("$venv/bin/python" --version), numpy $("$venv/bin/python" -c 'import numpy; print(numpy.__version__)'):" \
        "$CORE_NAMES, not slow"
    # Its own status: called as `run_version || status=1`, the function runs without `set -e`.
    local rc=0
    HYPOTHESIS_PROFILE=interpreters "$venv/bin/python" -m pytest -q -n "$(nproc)" -p no:cacheprovider \
        -m "not slow" "${CORE_TESTS[@]}" "$@" || rc=$?
    echo "== Python $version: $((SECONDS - start)) s"
    return "$rc"
}

total=$SECONDS
status=0
ran=()
for version in "${versions[@]}"; do
    run_version "$version" "$@" || status=1
done
if [[ ${#ran[@]} -gt 0 ]]; then
    echo "== the core tests on Python ${ran[*]}: $((SECONDS - total)) s"
fi
exit $status
