# Sourced by scripts/test.sh and scripts/fuzz.sh: install_debian_packages PKG... installs the
# Debian packages that are missing (apt-get, with sudo when not root) and does nothing otherwise.
install_debian_packages() {
    local missing=() pkg sudo=()
    for pkg in "$@"; do
        dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
    done
    if ((${#missing[@]})); then
        echo "== installing Debian packages: ${missing[*]}"
        [[ $(id -u) -eq 0 ]] || sudo=(sudo)
        "${sudo[@]}" apt-get update -qq
        DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq "${missing[@]}" >/dev/null
    fi
}
