# Sourced by the scripts that install this checkout into a venv: how they install it, and when
# again.
#
# setuptools' `strict` editable mode: site-packages gets a .pth naming a tree of links to the
# packages' files (build/__editable__.*), so type checkers follow it (the default mode's import
# hook they cannot) and only protocol, host_sdk, emulator and roverlink are importable, not the
# checkout's tests, tools or benchmarks. A file added to or removed from a package needs the
# install again: `editable_digest` names the packages' file list, and a venv whose stamp has
# another digest is installed again.
EDITABLE_MODE=strict

editable_digest() {
    (cd "$ROOT" && find protocol host_sdk emulator roverlink -type f ! -path '*/__pycache__/*' \
        | LC_ALL=C sort | sha1sum | cut -c1-12)
}
