#!/usr/bin/env bash
# The project's test command (README): sets up what the tests need, then runs
# `cargo test --workspace` inside a network namespace that has only loopback, so no DDS
# discovery traffic leaves the machine. Needs root (ip netns); CI runs as root.
#   - target/venv: Python with cyclonedds (the interop peer of tests/cyclonedds_interop.rs) and
#     rosbags, mcap, mcap-ros2-support (the readers of tests/recording.rs)
#   - Debian's chromium and Node.js, and target/npm: playwright-core, which drives that chromium
#     in tests/web_hmi.rs (it never downloads a browser of its own)
#   - Debian's linuxcnc-uspace (2.9.0~pre1 in bookworm): its standalone interpreter rs274 is
#     the reference of tests/linuxcnc_oracle.rs (../shared/notes/linuxcnc_oracle.md)
set -euo pipefail
cd "$(dirname "$0")/.."
if ! target/venv/bin/python -c "import cyclonedds, rosbags, mcap, mcap_ros2, lz4, zstandard" 2>/dev/null; then
    python3 -m venv target/venv
    target/venv/bin/pip install --quiet --disable-pip-version-check cyclonedds==11.0.1 \
        rosbags==0.11.9 mcap==1.6.0 mcap-ros2-support==0.6.0 lz4==4.4.5 zstandard==0.25.0
fi
if ! command -v chromium >/dev/null || ! command -v node >/dev/null || ! command -v npm >/dev/null; then
    apt-get update
    apt-get install -y chromium nodejs npm
fi
if ! command -v rs274 >/dev/null; then
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends linuxcnc-uspace
fi
if [ ! -f target/npm/node_modules/playwright-core/package.json ]; then
    mkdir -p target/npm
    npm install --prefix target/npm --no-audit --no-fund --silent playwright-core@1.64.1
fi
NS="cnc_test_$$"
cleanup() { ip netns del "$NS" 2>/dev/null || true; }
trap cleanup EXIT
ip netns add "$NS"
ip netns exec "$NS" ip link set lo up
ip netns exec "$NS" ip link set lo multicast on
ip netns exec "$NS" ip route add 224.0.0.0/4 dev lo
cargo build --workspace --tests
ip netns exec "$NS" cargo test --workspace "$@"
