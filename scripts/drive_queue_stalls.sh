#!/usr/bin/env bash
# Issue 48, must-show 1, the full table: the lathe's and the mill's part with the drives'
# setpoint queue (100 ms), the motion process stopped (SIGSTOP/SIGCONT) for 5, 10, 20, 40 and
# 80 ms at STALLS (default 50) random moments each, during back-to-back `cargo build`s of the
# workspace; prints per machine and stall length the stalls made, the underruns, the least
# queue depth and whether the drive trace's path is the undisturbed run's: "identical" (every
# bit), "same" (a thread's setpoints differ in their last bits, as between any two runs:
# `tests/common/queued_cell.rs::Comparison`) or DIFFERENT (`tests/drive_queue.rs::stall_table`).
# DDS stays in a network namespace with only loopback.
#   scripts/drive_queue_stalls.sh [STALLS]
# CNC_TABLE_MACHINE=lathe1|mill1 and CNC_STALL_LENGTHS=5,80 run a part of the table.
set -euo pipefail
cd "$(dirname "$0")/.."
export CNC_STALLS="${1:-50}"
cargo build --workspace --tests
LOAD_DIR="target/stall-load"
NS="cnc_stalls_$$"
cleanup() {
    [ -n "${LOAD_PID:-}" ] && kill -- -"$LOAD_PID" 2>/dev/null || true
    ip netns del "$NS" 2>/dev/null || true
}
trap cleanup EXIT
ip netns add "$NS"
ip netns exec "$NS" ip link set lo up
ip netns exec "$NS" ip link set lo multicast on
ip netns exec "$NS" ip route add 224.0.0.0/4 dev lo
set -m
( while true; do rm -rf "$LOAD_DIR"; cargo build --workspace --target-dir "$LOAD_DIR" -q >/dev/null 2>&1 || true; done ) &
LOAD_PID=$!
set +m
echo "load: cargo build (pid $LOAD_PID); $CNC_STALLS stalls per length"
ip netns exec "$NS" cargo test --test drive_queue stall_table -- --ignored --nocapture 2>&1 \
    | grep -E -A4 "^(machine|lathe1|mill1) |test result|panicked"
