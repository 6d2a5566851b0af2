#!/usr/bin/env bash
# What the tests need, each piece installed only when it is missing, one step at a time.
# scripts/test.sh runs it first; .ci/run also runs it with --plan.
#
#   step        present when                    else
#   system      `ip` and Python's venv work     apt: iproute2 python3-venv
#   openssl     OpenSSL's headers for DDS       apt: libssl-dev pkg-config (the build of
#               Security (rustdds, `openssl`)        rustdds's security feature links OpenSSL)
#   chromium    `chromium` is on PATH           apt: chromium (the browser of tests/web_hmi.rs)
#   node        `node` and `npm` are on PATH    apt: nodejs npm (a machine of the CI's kind has
#                                               both from NodeSource, whose nodejs conflicts
#                                               with Debian's npm: never installed over it)
#   rs274       `rs274` is on PATH              apt: linuxcnc-uspace (tests/linuxcnc_oracle.rs)
#   venv        target/venv imports them all    pip: cyclonedds, rosbags, mcap, ... (interop peers)
#   playwright  target/npm has playwright-core  npm: playwright-core (drives Debian's chromium)
#
# scripts/setup.sh          install what is missing; a failed step says which and why, exit 1
# scripts/setup.sh --plan   install nothing: check, with `apt-get -s`, the plan of every apt
#                           step a fresh machine would run, against the package state of a
#                           fresh machine (this one's without what these steps installed), so a
#                           machine that already has everything still finds a step that would
#                           fail on a fresh one
set -euo pipefail
cd "$(dirname "$0")/.."
export DEBIAN_FRONTEND=noninteractive

# The apt steps: name, the commands that prove the piece present, the packages.
APT_STEPS=(
    "system|ip python3-venv|iproute2 python3-venv"
    "openssl|openssl-dev|libssl-dev pkg-config"
    "chromium|chromium|chromium"
    "node|node npm|nodejs npm"
    "rs274|rs274|linuxcnc-uspace"
)
PIP_PACKAGES="cyclonedds==11.0.1 rosbags==0.11.9 mcap==1.6.0 mcap-ros2-support==0.6.0 lz4==4.4.5 zstandard==0.25.0"
PLAYWRIGHT="playwright-core@1.64.1"
LOG="$(mktemp)"
trap 'rm -f "$LOG"' EXIT

say() { echo "setup: $*"; }

# Runs a step's command with its output in $LOG; on failure names the step, the command, its
# exit code and apt's or pip's own reason (the last lines it printed), and stops the script.
run_step() {
    local step="$1"
    shift
    local rc=0
    "$@" >"$LOG" 2>&1 || rc=$?
    if [ "$rc" -ne 0 ]; then
        echo "setup: step '$step' FAILED: \`$*\` exited $rc; its last lines:" >&2
        tail -n 15 "$LOG" | sed 's/^/    /' >&2
        exit 1
    fi
}

# Whether the piece a guard word names is here: a command on PATH, or (python3-venv) Python's
# venv with ensurepip.
present() {
    case "$1" in
        python3-venv) python3 -c "import venv, ensurepip" 2>/dev/null ;;
        openssl-dev) pkg-config --exists openssl 2>/dev/null ;;
        *) command -v "$1" >/dev/null ;;
    esac
}

APT_UPDATED=""
apt_update() {
    if [ -z "$APT_UPDATED" ]; then
        run_step "apt-get update" apt-get update
        APT_UPDATED=1
    fi
}

install_apt_steps() {
    local entry step guards packages g missing
    for entry in "${APT_STEPS[@]}"; do
        IFS='|' read -r step guards packages <<<"$entry"
        missing=""
        for g in $guards; do present "$g" || missing="$missing $g"; done
        if [ -z "$missing" ]; then
            say "$step: present"
            continue
        fi
        say "$step: missing$missing: apt-get install $packages"
        apt_update
        run_step "$step" apt-get install -y --no-install-recommends $packages
        for g in $guards; do
            if ! present "$g"; then
                echo "setup: step '$step' FAILED: $packages installed, but $g is still missing" >&2
                exit 1
            fi
        done
    done
}

install_venv() {
    if target/venv/bin/python -c "import cyclonedds, rosbags, mcap, mcap_ros2, lz4, zstandard" 2>/dev/null; then
        say "venv: present"
        return
    fi
    say "venv: target/venv with $PIP_PACKAGES"
    run_step venv python3 -m venv target/venv
    run_step venv target/venv/bin/pip install --quiet --disable-pip-version-check $PIP_PACKAGES
}

install_playwright() {
    if [ -f target/npm/node_modules/playwright-core/package.json ]; then
        say "playwright: present"
        return
    fi
    say "playwright: target/npm with $PLAYWRIGHT"
    mkdir -p target/npm
    run_step playwright npm install --prefix target/npm --no-audit --no-fund --silent "$PLAYWRIGHT"
}

# What a fresh machine of the CI's kind lacks (/work/.library/env/machines/rust.md: Rust,
# Python 3.11, Node.js 20 and npm 11 from NodeSource, iproute2, python3-venv; no chromium, no rs274).
FRESH_LACKS="chromium rs274"

# The dpkg status of a fresh machine: this one's without the packages that provide the commands
# a fresh machine lacks, and the dependencies that came with them (what
# `apt-get purge --autoremove` of them would take).
fresh_status() {
    local out="$1" c owners="" gone=""
    for c in $FRESH_LACKS; do
        if command -v "$c" >/dev/null; then
            owners="$owners $(dpkg -S "$(readlink -f "$(command -v "$c")")" 2>/dev/null | head -n 1 | cut -d: -f1)"
        fi
    done
    if [ -n "${owners// /}" ]; then
        gone=$(apt-get -s purge --autoremove $owners 2>/dev/null | awk '/^Purg /{print $2}' | tr '\n' ' ')
        # What apt's history says came with them, also where something else recommends it.
        gone="$gone $(installed_with $owners)"
    fi
    awk -v gone=" $gone " 'BEGIN { RS = ""; ORS = "\n\n" }
        { split($0, l, "\n"); sub(/^Package: /, "", l[1]); sub(/:.*/, "", l[1]) }
        index(gone, " " l[1] " ") == 0 { print }' /var/lib/dpkg/status >"$out"
    FRESH_GONE="$gone"
}

# The packages apt's history (/var/log/apt/history.log*) installed in the same command as
# any of the given packages.
installed_with() {
    local logs
    logs=$(ls /var/log/apt/history.log* 2>/dev/null) || return 0
    for f in $logs; do
        case "$f" in *.gz) zcat "$f" ;; *) cat "$f" ;; esac
    done | awk -v want=" $* " '
        /^Start-Date:/ { ours = 0 }
        /^Install: / {
            line = substr($0, 10); n = split(line, e, /\), /)
            for (i = 1; i <= n; i++) { split(e[i], w, /[: ]/); names[i] = w[1]; if (index(want, " " w[1] " ")) ours = 1 }
            if (ours) for (i = 1; i <= n; i++) print names[i]
            delete names
        }' | sort -u | tr '\n' ' '
}

# Whether a guard word would be present on a fresh machine.
present_when_fresh() {
    case " $FRESH_LACKS " in
        *" $1 "*) return 1 ;;
        *) present "$1" ;;
    esac
}

plan() {
    local status entry step guards packages g missing count failed=0
    status="$(mktemp)"
    apt_update
    fresh_status "$status"
    say "plan: a fresh machine lacks $FRESH_LACKS; packages left out of its state: ${FRESH_GONE:-none (not installed here)}"
    for entry in "${APT_STEPS[@]}"; do
        IFS='|' read -r step guards packages <<<"$entry"
        missing=""
        for g in $guards; do present_when_fresh "$g" || missing="$missing $g"; done
        if [ -z "$missing" ]; then
            say "plan: $step: present on a fresh machine, not run"
            continue
        fi
        if apt-get -s -o Dir::State::status="$status" install -y --no-install-recommends $packages >"$LOG" 2>&1; then
            count=$(grep -c '^Inst ' "$LOG" || true)
            say "plan: $step: missing$missing: apt-get install $packages would install $count packages"
        else
            echo "setup: plan: step '$step' would FAIL on a fresh machine: apt-get install $packages:" >&2
            grep -E '^(E:| )' "$LOG" | tail -n 15 | sed 's/^/    /' >&2
            failed=1
        fi
    done
    rm -f "$status"
    return $failed
}

case "${1:-}" in
    --plan) plan ;;
    "")
        install_apt_steps
        install_venv
        install_playwright
        ;;
    *)
        echo "usage: scripts/setup.sh [--plan]" >&2
        exit 2
        ;;
esac
