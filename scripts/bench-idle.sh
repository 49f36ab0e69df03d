#!/usr/bin/env bash
# CPU share of the viewer at rest: each case starts the viewer under Xvfb (software Vulkan),
# waits until it has converged (its tracer threads idle), optionally clicks a pixel and waits
# again, then reads the process's CPU time over an idle interval from /proc (user + system,
# all threads: the UI, the tracer's and the driver's).
# Prints one line per case: scene, action, CPU % of one core over the interval.
# Usage: bash scripts/bench-idle.sh [MAX_SECONDS_TO_CONVERGE] [SECONDS_MEASURED]
# Needs: Xvfb, xdotool, mesa-vulkan-drivers (scripts/install-deps.sh installs them), and a
# release build (cargo build --release).
set -euo pipefail
cd "$(dirname "$0")/.."
converge="${1:-120}"
measure="${2:-20}"
bin=target/release/raytree
[ -x "$bin" ] || { echo "build first: cargo build --release" >&2; exit 1; }
display=:93
Xvfb "$display" -screen 0 1280x800x24 >/dev/null 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null || true' EXIT
sleep 1
ticks=$(getconf CLK_TCK)
cpu_ticks() { awk '{print $14 + $15}' "/proc/$1/stat"; }
# CPU ticks of the process's tracer threads (named raytree-*: the render and scene-view
# workers, the export); the rest is the UI thread and the driver's.
tracer_ticks() {
    local sum=0 t
    for t in /proc/"$1"/task/*; do
        if grep -q '^raytree' "$t/comm" 2>/dev/null; then
            sum=$((sum + $(awk '{print $14 + $15}' "$t/stat")))
        fi
    done
    echo "$sum"
}
# Waits (at most $converge s) until the tracer threads used no CPU for 3 s in a row.
wait_converged() {
    local pid="$1" waited=0 quiet=0 a b
    while [ "$waited" -lt "$converge" ] && [ "$quiet" -lt 3 ]; do
        a=$(tracer_ticks "$pid"); sleep 1; b=$(tracer_ticks "$pid")
        waited=$((waited + 1))
        if [ "$a" = "$b" ]; then quiet=$((quiet + 1)); else quiet=0; fi
    done
    [ "$quiet" -ge 3 ] || echo "  (not converged after ${converge}s)" >&2
}

run_case() {
    local label="$1" action="$2"; shift 2
    local runtime
    runtime=$(mktemp -d)
    DISPLAY="$display" WGPU_BACKEND=vulkan XDG_RUNTIME_DIR="$runtime" \
        HOME="$runtime" "$bin" "$@" >/dev/null 2>&1 &
    local pid=$!
    sleep 3
    wait_converged "$pid"
    if [ "$action" = click ]; then
        # The middle of the window: the render pane; then the pointer leaves the window.
        DISPLAY="$display" xdotool mousemove 640 400 click 1 || true
        sleep 1
        DISPLAY="$display" xdotool mousemove 1279 799 || true
        sleep 2
        wait_converged "$pid"
    fi
    local a b
    a=$(cpu_ticks "$pid")
    sleep "$measure"
    b=$(cpu_ticks "$pid")
    kill "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
    rm -rf "$runtime"
    awk -v l="$label" -v act="$action" -v d=$((b - a)) -v t="$ticks" -v s="$measure" \
        'BEGIN { printf "%-22s %-6s %5.1f %% of a core\n", l, act, 100 * d / t / s }'
}

run_case "built-in default" none
run_case "built-in default" click
run_case "quiz.toml (file)" none assets/scenes/quiz.toml
run_case "quiz.toml (file)" click assets/scenes/quiz.toml
run_case "room.obj (file)" none assets/models/room.obj
run_case "room.obj (file)" click assets/models/room.obj
