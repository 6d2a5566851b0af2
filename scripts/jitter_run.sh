#!/usr/bin/env bash
# Issue 4, item 6: runs the cell's servo loop on the simulated lathe for MINUTES (default 10)
# while a clean `cargo build` of the workspace runs alongside, again and again, on the same
# 2 cores; then prints the loop's tick statistics and interval histogram (late ticks
# included). DDS stays in a network namespace with only loopback.
#   scripts/jitter_run.sh [MINUTES]
set -euo pipefail
cd "$(dirname "$0")/.."
MINUTES="${1:-10}"
cargo build --release --workspace
BIN="$(mktemp -d)/cnc"
cp target/release/cnc "$BIN"      # the load build below must not replace the running binary
LOAD_DIR="target/jitter-load"
NS="cnc_jitter_$$"
cleanup() {
    [ -n "${LOAD_PID:-}" ] && kill -- -"$LOAD_PID" 2>/dev/null || true
    ip netns del "$NS" 2>/dev/null || true
}
trap cleanup EXIT
ip netns add "$NS"
ip netns exec "$NS" ip link set lo up
ip netns exec "$NS" ip link set lo multicast on
ip netns exec "$NS" ip route add 224.0.0.0/4 dev lo
# The load: clean debug builds of the whole workspace, back to back.
set -m
( while true; do rm -rf "$LOAD_DIR"; cargo build --workspace --target-dir "$LOAD_DIR" -q >/dev/null 2>&1 || true; done ) &
LOAD_PID=$!
set +m
echo "load: cargo build loop (pid $LOAD_PID); servo loop for $MINUTES min"
ip netns exec "$NS" timeout -s INT "$(awk "BEGIN{print int($MINUTES * 60)}")" \
    "$BIN" run launch_configs/sim_lathe.yaml --program examples/lathe/demo_shaft.nc --cycles 0 \
    2>&1 | tail -40 || true
