#!/usr/bin/env bash
# What DDS Security's protection costs (D113): the simulated lathe runs ROUNDS times each of
# `cnc run CONFIG --program short part --cycles CYCLES` without security, under
# `--protection sign` and under `--protection encrypt` (one process: the machine's nodes and
# the launcher's supervisor client), interleaved so a change in the machine's load falls on
# all three alike. Prints per mode the median wall time and CPU time (user + system) of the
# run, and their ratio to the run without security. DDS stays in a loopback-only network
# namespace. Needs root (ip netns).
#   scripts/dds_protection_cost.sh [ROUNDS] [CYCLES]
set -euo pipefail
cd "$(dirname "$0")/.."
ROUNDS="${1:-3}"
CYCLES="${2:-3}"
cargo build --release --bin cnc
BIN=target/release/cnc
WORK="$(mktemp -d)"
NS="cnc_protection_$$"
cleanup() { ip netns del "$NS" 2>/dev/null || true; rm -rf "$WORK"; }
trap cleanup EXIT
ip netns add "$NS"
ip netns exec "$NS" ip link set lo up
ip netns exec "$NS" ip link set lo multicast on
ip netns exec "$NS" ip route add 224.0.0.0/4 dev lo

printf 'O0001\nG98 G97 S500 M03\nG00 X100 Z5\nG01 Z-10 F1500\nG00 X150 Z50\nM05\nM30\n' > "$WORK/part.nc"
for mode in none sign encrypt; do
    sed -e '/^recorder:/,/^[a-z]/ s/enabled: true/enabled: false/' \
        -e 's/^  web_address:.*/  web_address: ""/' launch_configs/sim_lathe.yaml > "$WORK/$mode.yaml"
    if [ "$mode" != none ]; then
        "$BIN" security init "$WORK/keystore_$mode" --machine lathe1 --protection "$mode" > /dev/null
        sed -i "s|^network:|network:\n  security: {keystore: $WORK/keystore_$mode}|" "$WORK/$mode.yaml"
    fi
done

declare -A WALL CPU
for round in $(seq 1 "$ROUNDS"); do
    for mode in none sign encrypt; do
        out="$WORK/time_${mode}_${round}"
        ip netns exec "$NS" /usr/bin/env time -f '%e %U %S' -o "$out" \
            "$BIN" run "$WORK/$mode.yaml" --program "$WORK/part.nc" --cycles "$CYCLES" \
            > "$WORK/log_${mode}_$round" 2>&1 || { echo "$mode round $round failed:"; tail -5 "$WORK/log_${mode}_$round"; exit 1; }
        read -r wall user sys < "$out"
        WALL[$mode]+="$wall "
        CPU[$mode]+="$(echo "$user + $sys" | bc) "
    done
done

median() { tr ' ' '\n' | grep -v '^$' | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
base_wall=$(echo "${WALL[none]}" | median)
base_cpu=$(echo "${CPU[none]}" | median)
printf '%-8s %10s %10s %10s %10s   (%s rounds, %s cycles each)\n' mode wall_s cpu_s wall/none cpu/none "$ROUNDS" "$CYCLES"
for mode in none sign encrypt; do
    w=$(echo "${WALL[$mode]}" | median)
    c=$(echo "${CPU[$mode]}" | median)
    printf '%-8s %10s %10s %10.2f %10.2f\n' "$mode" "$w" "$c" "$(echo "$w / $base_wall" | bc -l)" "$(echo "$c / $base_cpu" | bc -l)"
done
