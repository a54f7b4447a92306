# Sourced by scripts/test.sh: `stage NAME COMMAND...` runs one stage, prints its header and
# remembers how long it took; on exit (success or failure) a table of the stage times and the
# total is printed, with a warning when the total passes the budget's warning line.
#
#   STAGE_WARN_S   total seconds past which the summary warns (default 1500: 25 of CI's 30 minutes)

STAGE_WARN_S=${STAGE_WARN_S:-1500}
_stage_names=()
_stage_seconds=()
_stage_start_all=$EPOCHREALTIME

_stage_current=""
_stage_start=""

# Not `"$@" || ...`: that would turn off `set -e` inside the stage's own functions and scripts.
stage() {
    _stage_current=$1
    _stage_start=$EPOCHREALTIME
    shift
    echo "== $_stage_current"
    "$@"
    _stage_record
}

_stage_record() {
    _stage_names+=("$_stage_current")
    _stage_seconds+=("$(_stage_elapsed "$_stage_start")")
    _stage_current=""
}

_stage_elapsed() {
    awk -v a="$1" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.1f", b - a }'
}

_stage_summary() {
    local status=$? total i
    [[ -n $_stage_current ]] && _stage_record
    total=$(_stage_elapsed "$_stage_start_all")
    echo
    echo "== stage times"
    for i in "${!_stage_names[@]}"; do
        printf '   %7s s  %s\n' "${_stage_seconds[$i]}" "${_stage_names[$i]}"
    done
    printf '   %7s s  total (%s min)%s\n' "$total" "$(awk -v t="$total" 'BEGIN { printf "%.1f", t / 60 }')" \
        "$( ((status)) && echo ", stopped by a failing stage")"
    if awk -v t="$total" -v w="$STAGE_WARN_S" 'BEGIN { exit !(t > w) }'; then
        echo "WARNING: the run took longer than ${STAGE_WARN_S} s, the warning line of CI's 30-minute" \
            "limit: find the stage that grew (docs/testing.md, 'Time')"
    fi
    return "$status"
}
trap _stage_summary EXIT
