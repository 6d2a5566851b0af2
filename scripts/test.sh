#!/usr/bin/env bash
# Runs every test. DDS tests run inside a network namespace that has only loopback, so no
# discovery traffic leaves the machine. Needs root (ip netns); CI runs as root.
set -euo pipefail
cd "$(dirname "$0")/.."
NS="cnc_test_$$"
cleanup() { ip netns del "$NS" 2>/dev/null || true; }
trap cleanup EXIT
ip netns add "$NS"
ip netns exec "$NS" ip link set lo up
ip netns exec "$NS" ip link set lo multicast on
ip netns exec "$NS" ip route add 224.0.0.0/4 dev lo
cargo build --workspace --tests
ip netns exec "$NS" cargo test --workspace "$@"
