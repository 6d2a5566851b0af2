#!/usr/bin/env bash
# Speed of two revisions, measured by alternating their benchmark binaries in one run, so a
# busy machine slows both alike: the interpreter (`interpret`), the planner and servo tick
# (`motion`) and the PLC scan (`plc_scan`).
#
#   scripts/bench_ab.sh OLD_REV [NEW_REV] [ROUNDS]
#
# Builds each revision's benches in a worktree of its own beside the repository (the motion
# bench reads ../shared/bench from its source folder; target dirs under
# ${BENCH_AB_DIR:-/tmp/cnc_bench_ab}), then runs old, new, old, new … ROUNDS times each and
# prints the figures that measure speed, one line per run, tagged old/new. NEW_REV defaults to
# the working tree (uncommitted changes included), ROUNDS to 3.
set -euo pipefail

old_rev=${1:?usage: scripts/bench_ab.sh OLD_REV [NEW_REV] [ROUNDS]}
new_rev=${2:-}
rounds=${3:-3}
repo=$(cd "$(dirname "$0")/.." && pwd)
work=${BENCH_AB_DIR:-/tmp/cnc_bench_ab}
mkdir -p "$work"

# build REV|"" NAME: the three bench binaries of a revision, their paths in $work/NAME.bins
build() {
    local rev=$1 name=$2 src
    if [ -n "$rev" ]; then
        src=$(dirname "$repo")/cnc_bench_ab_$name
        rm -rf "$src"
        git -C "$repo" worktree add -f --detach "$src" "$rev" >/dev/null
    else
        src=$repo
    fi
    (cd "$src" && CARGO_TARGET_DIR=$work/$name.target cargo bench --workspace --no-run \
        --bench interpret --bench motion --bench plc_scan --message-format=json 2>/dev/null) |
        python3 -c '
import json, sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("executable") and "bench" in m["target"]["kind"]:
        print(m["target"]["name"], m["executable"])
' >"$work/$name.bins"
    echo "$name ($rev): $(wc -l <"$work/$name.bins") bench binaries" >&2
}

# run NAME: each bench once, the lines that measure speed
run() {
    local name=$1 bench exe
    while read -r bench exe; do
        case $bench in
        interpret) "$exe" | grep -E "^(reference|interpreter|ratio)" ;;
        motion) "$exe" | grep -E "motion CPU per servo tick" | head -2 ;;
        plc_scan) "$exe" | grep -E "^(scan time|images alone)" ;;
        esac | sed "s/^/$name $bench: /"
    done <"$work/$name.bins"
}

build "$old_rev" old
build "$new_rev" new
for ((i = 1; i <= rounds; i++)); do
    run old
    run new
done
parent=$(dirname "$repo")
if [ -n "$new_rev" ]; then git -C "$repo" worktree remove --force "$parent/cnc_bench_ab_new" || true; fi
git -C "$repo" worktree remove --force "$parent/cnc_bench_ab_old" || true
