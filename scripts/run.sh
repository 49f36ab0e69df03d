#!/usr/bin/env bash
# Opens the viewer on the built-in default scene (or on the scene given as an argument),
# installing and building what it needs first. Usage: bash scripts/run.sh [SCENE]
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/install-deps.sh
export PATH="$HOME/.cargo/bin:$PATH"
cargo build --release --locked
if [ -z "${DISPLAY:-}" ] && [ -z "${WAYLAND_DISPLAY:-}" ]; then
  echo "no display: starting a virtual one (Xvfb :99); take screenshots with 'import -display :99 -window root shot.png'" >&2
  Xvfb :99 -screen 0 1600x1000x24 >/dev/null 2>&1 &
  export DISPLAY=:99
  sleep 1
fi
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
exec ./target/release/raytree "$@"
