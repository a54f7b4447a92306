# Sourced by scripts/demo.sh and scripts/test.sh: makes sure the checkout has its own virtual
# environment (.venv) with this package installed in it (editable, with the extras asked for),
# so nothing is installed into the system's Python (Debian 12 / Raspberry Pi OS refuse that: PEP 668).
#
#   source scripts/venv.sh [EXTRA,...]     then: "$VENV/bin/python", "$VENV/bin/roverlink", ...
#
# The venv is made with `python3` from PATH (or $PYTHON). Debian's python3 needs its venv module,
# the package python3-venv: installed with apt-get when missing (sudo when not root).
#
# SYSTEM_SITE_PACKAGES=1 makes it with --system-site-packages, so it sees the system's own numpy,
# OpenCV, picamera2 and ROS 2 (Raspberry Pi OS, JetPack, Ubuntu with ROS: docs/sensors.md#one-route-per-platform),
# and keeps them: the system's numpy is pinned while installing, and the extras that bring the
# PyPI OpenCV (vision, console, dev; it needs numpy 2) are refused. Run it alone to make the venv:
#
#   SYSTEM_SITE_PACKAGES=1 PYTHON=/usr/bin/python3 bash scripts/venv.sh tools

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="$ROOT/.venv"
PYTHON="${PYTHON:-python3}"
EXTRAS="${1:-}"
SYSTEM_SITE_PACKAGES="${SYSTEM_SITE_PACKAGES:-}"

venv_fail() {
    echo "error: $*" >&2
}

if [[ "$SYSTEM_SITE_PACKAGES" == 1 ]]; then
    for extra in ${EXTRAS//,/ }; do
        case "$extra" in
            vision | console | dev)
                venv_fail "SYSTEM_SITE_PACKAGES=1: the $extra extra brings PyPI's OpenCV, whose numpy 2 would" \
                    "replace the system's; leave it out (the system's OpenCV is used: docs/sensors.md#one-route-per-platform)"
                return 1 2>/dev/null || exit 1 ;;
        esac
    done
fi

as_root() {
    if [[ $(id -u) -eq 0 ]]; then "$@"; else sudo "$@"; fi
}

apt_install() {
    echo "== installing Debian packages: $*"
    as_root apt-get update -qq
    DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq "$@" >/dev/null
}

if ! command -v "$PYTHON" >/dev/null; then
    apt_install python3
fi

if [[ ! -x "$VENV/bin/python" ]] || ! "$VENV/bin/python" -m pip --version >/dev/null 2>&1; then
    if ! "$PYTHON" -c 'import ensurepip, venv' >/dev/null 2>&1; then
        version="$("$PYTHON" -c 'import sys; print("%d.%d" % sys.version_info[:2])')"
        apt_install python3-venv "python${version}-venv"
    fi
    venv_args=()
    [[ "$SYSTEM_SITE_PACKAGES" == 1 ]] && venv_args=(--system-site-packages)
    echo "== creating the virtual environment $VENV ($("$PYTHON" --version)${venv_args:+, ${venv_args[0]}})"
    rm -rf "$VENV"
    "$PYTHON" -m venv "${venv_args[@]}" "$VENV"
fi
# A venv made the other way is not changed behind its owner's back: it says so.
sees_system=false
grep -qiE '^include-system-site-packages *= *true' "$VENV/pyvenv.cfg" && sees_system=true
if [[ "$SYSTEM_SITE_PACKAGES" == 1 && "$sees_system" == false ]]; then
    venv_fail "$VENV was made without --system-site-packages: delete it (rm -rf $VENV) to make it again"
    return 1 2>/dev/null || exit 1
fi
PIP_PINS=()
if [[ "$sees_system" == true ]]; then
    # The system's numpy stays: an install that needs another fails here instead of hiding it.
    if system_numpy="$("$VENV/bin/python" -c 'import numpy; print(numpy.__version__)' 2>/dev/null)"; then
        echo "numpy==$system_numpy" >"$VENV/constraints-system.txt"
        PIP_PINS=(--constraint "$VENV/constraints-system.txt")
    fi
fi

# shellcheck source=scripts/editable.sh
source "$ROOT/scripts/editable.sh"
EDITABLE_TAG="$EDITABLE_MODE-$(editable_digest)"
# Install (again) when pyproject.toml is newer than the last install with these extras, this mode
# and these package files (both in the stamp's name: a venv installed the old way, or before a
# module was added, is installed again).
# An install with more extras serves one that asks for fewer (the fast lane after a full run).
stamp="$VENV/.installed-$EDITABLE_TAG${EXTRAS:+-$EXTRAS}"
_venv_has_extras() {
    local file have want
    for file in "$VENV"/.installed-"$EDITABLE_TAG"*; do
        [[ -f "$file" && ! "$ROOT/pyproject.toml" -nt "$file" ]] || continue
        have=",$(basename "$file" | sed -e "s/^\.installed-$EDITABLE_TAG-\{0,1\}//"),"
        for want in ${EXTRAS//,/ }; do
            [[ $have == *",$want,"* ]] || continue 2
        done
        return 0
    done
    return 1
}
# An install with other extras may bring every package these need (`dev` has `plot`'s matplotlib,
# `tools`'s ...): then nothing is installed, so `demo.sh --plot` after `test.sh` installs nothing.
_venv_serves_extras() {
    local file current=false
    for file in "$VENV"/.installed-"$EDITABLE_TAG"*; do
        [[ -f "$file" && ! "$ROOT/pyproject.toml" -nt "$file" ]] && current=true
    done
    [[ $current == true && -n "$EXTRAS" ]] || return 1
    "$VENV/bin/python" - "$EXTRAS" <<'PY' >/dev/null 2>&1
import re
import sys
from importlib import metadata

wanted = set(filter(None, sys.argv[1].split(",")))
for requirement in metadata.requires("roverlink") or []:
    extra = re.search(r"extra\s*==\s*[\"']([^\"']+)[\"']", requirement)
    if extra and extra.group(1) in wanted:
        metadata.version(re.split(r"[\s;<>=!~\[(]", requirement, maxsplit=1)[0])  # raises when missing
PY
}
if ! _venv_has_extras && ! _venv_serves_extras; then
    echo "== installing roverlink${EXTRAS:+[$EXTRAS]} into $VENV"
    "$VENV/bin/python" -m pip install -q --disable-pip-version-check "${PIP_PINS[@]}" \
        --config-settings editable_mode="$EDITABLE_MODE" -e "$ROOT${EXTRAS:+[$EXTRAS]}"
    touch "$stamp"
fi
