#!/usr/bin/env bash
# Coverage-guided fuzzing of the firmware's untrusted inputs (tests/firmware/fuzz, SECURITY.md): installs
# clang 14 and libFuzzer from Debian when missing, builds the targets with ASan + UBSan, runs each
# for a bounded time and fails on any finding (the input is kept in build/fuzz/findings/).
#
#   bash scripts/fuzz.sh                          # the targets at once for 60 s: what the test script runs
#   bash scripts/fuzz.sh --seconds 3600           # as long as you like
#   bash scripts/fuzz.sh --targets "decoder config"
#   bash scripts/fuzz.sh --coverage               # then the library's line coverage on the corpus
#
# FUZZ_SECONDS in the environment sets the default time per target.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${FUZZ_SECONDS:-60}
targets="decoder firmware config"
coverage=0
while (($#)); do
    case $1 in
        --seconds) seconds=$2; shift 2 ;;
        --targets) targets=$2; shift 2 ;;
        --coverage) coverage=1; shift ;;
        *) echo "usage: $0 [--seconds N] [--targets \"decoder firmware config\"] [--coverage]" >&2; exit 2 ;;
    esac
done

source scripts/debian-packages.sh
install_debian_packages clang-14 libfuzzer-14-dev libclang-rt-14-dev llvm-14 make

echo "== building the fuzz targets ($targets)"
make -s -C tests/firmware/fuzz -j2 TARGETS="$targets" >/dev/null
# every target at once, for the time given: on two cores three targets get two thirds of a core
# each, and the stage takes its time once, not twice (docs/testing.md#time)
jobs=$(wc -w <<<"$targets")
make -s -C tests/firmware/fuzz -j"$jobs" fuzz TARGETS="$targets" SECONDS="$seconds"
if ((coverage)); then
    echo "== line coverage on the corpus"
    make -s -C tests/firmware/fuzz coverage TARGETS="$targets"
fi
