#!/usr/bin/env bash
# The project's test command (README): installs what the tests need (scripts/setup.sh: each
# missing piece on its own step), then runs `cargo test --workspace` inside a network namespace
# that has only loopback, so no DDS discovery traffic leaves the machine. Needs root (apt,
# ip netns); CI runs as root. Arguments go to `cargo test`.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
NS="cnc_test_$$"
cleanup() { ip netns del "$NS" 2>/dev/null || true; }
trap cleanup EXIT
ip netns add "$NS"
ip netns exec "$NS" ip link set lo up
ip netns exec "$NS" ip link set lo multicast on
ip netns exec "$NS" ip route add 224.0.0.0/4 dev lo
cargo build --workspace --tests
# A hung test binary fails the run with its stacks (scripts/test_runner.sh).
export CARGO_TARGET_X86_64_UNKNOWN_LINUX_GNU_RUNNER="$PWD/scripts/test_runner.sh"
ip netns exec "$NS" cargo test --workspace "$@"
