#!/usr/bin/env bash
# The first command of the README: an emulated robot drives a 1 m square and the SDK compares its
# odometry with ground truth. Makes the checkout's .venv on the first run (scripts/venv.sh).
# Any arguments go to `roverlink demo` (see `bash scripts/demo.sh --help`), e.g.
#   bash scripts/demo.sh --profile picar --plot square.png
set -euo pipefail
extras=""
for arg in "$@"; do
    [[ "$arg" == --plot* ]] && extras="plot"
done
# shellcheck source=scripts/venv.sh
source "$(dirname "$0")/venv.sh" "$extras"
exec "$VENV/bin/roverlink" demo "$@"
