#!/usr/bin/env bash
# cargo's runner for the test binaries while scripts/test.sh runs them (set there through
# CARGO_TARGET_<triple>_RUNNER, so `cargo run` and the cell are not affected). A binary that is
# still running after CNC_TEST_BINARY_LIMIT seconds (default 900; the longest binary takes
# about 150 s here) is hung, not slow: its threads' stacks are printed with gdb and it is
# killed, so the run fails with where it hung instead of reaching CI's own timeout.
set -uo pipefail
limit="${CNC_TEST_BINARY_LIMIT:-900}"
"$@" &
test_pid=$!

watch() {
    sleep "$limit" </dev/null >/dev/null 2>&1 &
    local sleeper=$!
    trap 'kill "$sleeper" 2>/dev/null; exit 0' TERM
    wait "$sleeper"
    kill -0 "$test_pid" 2>/dev/null || exit 0
    echo "test_runner: $1 still runs after ${limit} s: its threads, then kill -9" >&2
    if command -v gdb >/dev/null; then
        timeout 120 gdb -p "$test_pid" -batch -ex "thread apply all bt" </dev/null >&2 2>&1
    fi
    pkill -9 -P "$test_pid" 2>/dev/null
    kill -9 "$test_pid" 2>/dev/null
}
watch "$1" &
watcher=$!
wait "$test_pid"
rc=$?
kill "$watcher" 2>/dev/null
wait "$watcher" 2>/dev/null
exit "$rc"
