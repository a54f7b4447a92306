#!/usr/bin/env bash
# The distribution's camera route, tested as docs/sensors.md#cameras installs it: Debian's own
# Python (/usr/bin/python3) with its python3-opencv (built with GStreamer), numpy and
# gstreamer1.0-plugins-base, and RoverLink installed without the vision extra into a venv made with
# --system-site-packages (.venv-system). tests/host_sdk/sensors/test_camera_system_opencv.py then
# checks that the system's numpy and cv2 are the ones imported, and reads a videotestsrc pipeline
# through CameraSource and `roverlink record --camera`. A second venv (.venv-system-numpy2) puts a
# pip numpy 2 in front of the system's, as the OpenCV wheel does, to check the one-line report.
#
#   bash scripts/test_system_opencv.sh [pytest args]
#
# Debian packages missing are installed with apt-get (sudo when not root).
set -euo pipefail
cd "$(dirname "$0")/.."

SYSTEM_PYTHON=/usr/bin/python3
# shellcheck source=scripts/debian-packages.sh
source scripts/debian-packages.sh
ROOT="$PWD"
# shellcheck source=scripts/editable.sh
source scripts/editable.sh
EDITABLE_TAG="$EDITABLE_MODE-$(editable_digest)"
install_debian_packages python3 python3-venv python3-opencv gstreamer1.0-plugins-base

start=$SECONDS
before="$("$SYSTEM_PYTHON" -c 'import cv2, numpy; print(numpy.__version__, numpy.__file__, cv2.__version__, cv2.__file__)')"

make_venv() {
    local venv="$1" stamp="$1/.installed-system-$EDITABLE_TAG-$2"
    shift 2
    if [[ ! -x "$venv/bin/python" ]] || ! "$venv/bin/python" -m pip --version >/dev/null 2>&1; then
        echo "== creating $venv ($("$SYSTEM_PYTHON" --version), --system-site-packages)"
        rm -rf "$venv"
        "$SYSTEM_PYTHON" -m venv --system-site-packages "$venv"
    fi
    if [[ ! -f "$stamp" || pyproject.toml -nt "$stamp" ]]; then
        echo "== installing into $venv: $*"
        "$venv/bin/python" -m pip install -q --disable-pip-version-check \
            --config-settings editable_mode="$EDITABLE_MODE" "$@"
        touch "$stamp"
    fi
}

# RoverLink with the foxglove extra (`roverlink record`), and what the test reads MCAP with: none
# of it brings numpy or OpenCV.
make_venv .venv-system foxglove -e ".[foxglove]" "pytest>=8" "mcap>=1.2"
make_venv .venv-system-numpy2 numpy2 -e . "numpy>=2"

after="$(.venv-system/bin/python -c 'import cv2, numpy; print(numpy.__version__, numpy.__file__, cv2.__version__, cv2.__file__)')"
if [[ "$after" != "$before" ]]; then
    echo "error: the venv imports another numpy or cv2 than the system's: $after (the system's: $before)" >&2
    exit 1
fi
echo "== the system's numpy and OpenCV, seen from .venv-system: $after"

ROVERLINK_REQUIRE_SYSTEM_OPENCV=1 ROVERLINK_NUMPY2_PYTHON="$PWD/.venv-system-numpy2/bin/python" \
    .venv-system/bin/python -m pytest -q -p no:cacheprovider -W ignore::pytest.PytestConfigWarning \
    tests/host_sdk/sensors/test_camera_system_opencv.py "$@"
echo "== the system OpenCV route: $((SECONDS - start)) s"
