#!/usr/bin/env bash
# Runs the cell's servo loop on the simulated lathe for MINUTES (default 10) under a load on
# the same 2 cores, then prints the loop's tick statistics and interval histogram (late ticks
# included). DDS stays in a network namespace with only loopback.
#   scripts/jitter_run.sh [MINUTES] [LOAD]
# LOAD: `build` (default: clean `cargo build`s of the workspace, back to back) or `hogs` (one
# busy loop per core and a disk writer). REALTIME=0 runs with the launch config's real-time
# priorities at 0 (ordinary threads, as before issue 27), for a comparison on the same machine.
# QUEUE_MS=100 runs the drives on their own clock with a setpoint queue that long (issue 48):
# the summary then has motion's planning loop and the drives' loop (underruns, least queue
# depth, the drives' own lateness histogram) apart.
set -euo pipefail
cd "$(dirname "$0")/.."
MINUTES="${1:-10}"
LOAD="${2:-build}"
cargo build --release --workspace
BIN="$(mktemp -d)/cnc"
cp target/release/cnc "$BIN"      # the load build below must not replace the running binary
LOAD_DIR="target/jitter-load"
NS="cnc_jitter_$$"
CONFIG=launch_configs/sim_lathe.yaml
if [ "${REALTIME:-1}" = 0 ] || [ -n "${QUEUE_MS:-}" ]; then
    # Beside the original, so its relative paths still hold.
    CONFIG=launch_configs/.jitter_variant.yaml
    cp launch_configs/sim_lathe.yaml "$CONFIG"
    if [ -n "${QUEUE_MS:-}" ]; then
        sed -i "s/^servo:\$/servo:\n  drive_queue_ms: $QUEUE_MS/" "$CONFIG"
    fi
    if [ "${REALTIME:-1}" = 0 ]; then
        printf '\nrealtime:\n  servo_priority: 0\n  io_priority: 0\n  plc_priority: 0\n  lock_memory: false\n' >> "$CONFIG"
    fi
fi
cleanup() {
    [ -n "${LOAD_PID:-}" ] && kill -- -"$LOAD_PID" 2>/dev/null || true
    ip netns del "$NS" 2>/dev/null || true
    rm -f launch_configs/.jitter_variant.yaml "${SINK:-}"
}
trap cleanup EXIT
ip netns add "$NS"
ip netns exec "$NS" ip link set lo up
ip netns exec "$NS" ip link set lo multicast on
ip netns exec "$NS" ip route add 224.0.0.0/4 dev lo
set -m
case "$LOAD" in
    build)
        ( while true; do rm -rf "$LOAD_DIR"; cargo build --workspace --target-dir "$LOAD_DIR" -q >/dev/null 2>&1 || true; done ) &
        ;;
    hogs)
        SINK="$(mktemp -p target jitter-sink.XXXXXX)"
        ( ( while :; do :; done ) & ( while :; do :; done ) &
          ( while :; do dd if=/dev/zero of="$SINK" bs=1M count=256 conv=fsync status=none; done ) &
          wait ) &
        ;;
    *) echo "LOAD is build or hogs" >&2; exit 2 ;;
esac
LOAD_PID=$!
set +m
echo "load: $LOAD (pid $LOAD_PID); servo loop for $MINUTES min; config $CONFIG"
ip netns exec "$NS" timeout -s INT "$(awk "BEGIN{print int($MINUTES * 60)}")" \
    "$BIN" run "$CONFIG" --program examples/lathe/demo_shaft.nc --cycles 0 \
    2>&1 | tail -60 || true
