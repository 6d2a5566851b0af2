#!/usr/bin/env bash
# Issue 48, must-show 5: the cell on the simulated lathe with the drives' setpoint queue
# (QUEUE_MS, default 100) for MINUTES (default 30) under back-to-back `cargo build`s, its demo
# part in a loop; prints motion's planning-loop statistics and the drives' loop: underruns
# (goal 0), the least queue depth seen (goal ≥ 20 ms) and the drives' own wake-up lateness
# histogram (which a real drive's clock would not have). A benchmark, not a test.
#   scripts/drive_queue_soak.sh [MINUTES]
set -euo pipefail
cd "$(dirname "$0")/.."
QUEUE_MS="${QUEUE_MS:-100}" exec scripts/jitter_run.sh "${1:-30}" build
